/*
 * Private to the binding apair._native: what its translation units share. _native.c holds the
 * module (its initialisation and the kernel registry's calls), _native_chain.c the Chain type (one
 * chain's methods in one native call), _native_ik.c the inverse-kinematics solvers' marshaller and
 * LocalIK (ik_local's single-pose fast path).
 *
 * NumPy's C API in several files: every file includes this header, which names the API table
 * (PY_ARRAY_UNIQUE_SYMBOL); _native.c, which calls import_array(), defines APAIR_NATIVE_MODULE
 * first, and the others see the table as extern (NO_IMPORT_ARRAY).
 */
#ifndef APAIR_NATIVE_H
#define APAIR_NATIVE_H

#define PY_SSIZE_T_CLEAN
#include <Python.h>
#define NPY_NO_DEPRECATED_API NPY_1_7_API_VERSION
#define PY_ARRAY_UNIQUE_SYMBOL apair_native_ARRAY_API
#ifndef APAIR_NATIVE_MODULE
#define NO_IMPORT_ARRAY
#endif
#include <numpy/arrayobject.h>

#include <math.h>
#include <string.h>

#include "apair.h"

#define MAX_ARGS 16
#define MAX_DIMS NPY_MAXDIMS
#define NOGIL_COUNT 64 /* release the GIL from this batch size on */

/* _native_chain.c: the type apair._native.Chain, and enable(flag) (whether Chain.call may evaluate) */
extern PyTypeObject apair_native_chain_type;
PyObject *apair_native_enable(PyObject *self, PyObject *flag);
int apair_native_enabled(void); /* the flag enable() set */

/* _native_ik.c: the module's functions ik_* (NULL-terminated), and the type apair._native.LocalIK
 * (the single-pose fast path of AChain.ik_local) */
extern PyMethodDef apair_native_ik_methods[];
extern PyTypeObject apair_native_local_ik_type;
/* and the single-pose checks the fast paths share: obj a canonical float64 array of `size` doubles,
 * shape (size,) or (4, 4) (nd), finite, copied into out (1, else 0); T clearly rigid (1, else 0) */
int apair_native_canonical(PyObject *obj, int nd, npy_intp size, double *out);
int apair_native_rigid(const double *T);
/* and LAPACK for apair_ik6r_solve and apair_ik6r: SciPy's (scipy.linalg.cython_lapack), loaded on the
 * first call (with the GIL; NULL with an ImportError set where it cannot be) */
const apair_lapack *apair_native_lapack(void);

/* _native_closed.c: the type apair._native.ClosedIK (the single-pose fast path of AChain.ik for
 * the chains solved in closed form) */
extern PyTypeObject apair_native_closed_ik_type;

#endif
