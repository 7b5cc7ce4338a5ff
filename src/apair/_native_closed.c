/*
 * apair._native.ClosedIK: the single-pose fast path of AChain.ik for the chains solved in closed form
 * (apair.ik.forms: a family's form at the tool end or the base end): the design prepared once in C
 * (apair_ik_closed_init), and
 * call(T, tol), which solves one canonical pose or returns None for whatever the validating path
 * must see. Part of the binding apair._native (see _native.c; _native.h is what its files share).
 *
 * call takes exactly what the validating path (apair.ik.solver.Solver.solve) answers with the closed
 * form unchanged, with the C backend in use (apair.kernels enables the fast paths): T a float64
 * 4 x 4 ndarray (no subclass), finite, clearly rigid (apair_native_rigid, as LocalIK), its
 * translation within the chain's reach bound; tol a float > 0, finite. Anything else, and a pose
 * whose position polynomial vanishes (flags -1), returns None: the caller then takes the validating
 * path, which raises the one-line ValueError or answers by another method.
 */
#include "_native.h"

#define GENERAL_6R 128 /* six R-pairs of no closed-form family: the 6R elimination (apair_ik6r) */

typedef struct {
    PyObject_HEAD
    apair_ik_closed *solver; /* PyMem_Malloc'd (about 32 kB), prepared by apair_ik_closed_init; for
                              * GENERAL_6R only its family, dh and scale are set */
    const apair_lapack *lapack; /* GENERAL_6R: SciPy's */
    double reach; /* translations beyond it take the validating path (its reach bound answers) */
} ClosedIKObject;

static void closed_dealloc(ClosedIKObject *self)
{
    PyMem_Free(self->solver);
    Py_TYPE(self)->tp_free((PyObject *)self);
}

/* ClosedIK(family, dh, scale, reach, amplitude=None): family 1 (a spherical wrist), 2 (axes 2, 3, 4
 * parallel) or 3 (axes 1, 2, 3 parallel, 5 and 6 meeting), or'ed with 4 where it sits at the base end
 * (apair_ik_closed_init); or 8 or 16, a UR-like chain with sinusoidal A-pairs of amplitudes
 * amplitude (6,) at joint 3, or at joints 1 and 5, or 32 and 64, a spherical wrist's with one at
 * joint 3, or at joint 1 (apair_ik_closed_init_apair); or 128, any six R-pairs by the 6R elimination
 * (apair_ik6r, SciPy's LAPACK; a pose it does not certify returns None) */
static int closed_init(ClosedIKObject *self, PyObject *args, PyObject *kwds)
{
    PyObject *dh_obj, *amp_obj = Py_None;
    PyArrayObject *dh, *amp = NULL;
    double scale, reach;
    int family, apairs;
    (void)kwds;
    if (!PyArg_ParseTuple(args, "iOdd|O", &family, &dh_obj, &scale, &reach, &amp_obj)) {
        return -1;
    }
    apairs = family == APAIR_IK_PARALLEL_APAIR || family == APAIR_IK_PARALLEL_SLIDES || family == APAIR_IK_WRIST_APAIR ||
             family == APAIR_IK_WRIST_SLIDES;
    if (apairs) {
        amp = (PyArrayObject *)PyArray_FROM_OTF(amp_obj, NPY_DOUBLE, NPY_ARRAY_IN_ARRAY);
        if (amp == NULL) {
            return -1;
        }
        if (PyArray_NDIM(amp) != 1 || PyArray_DIM(amp, 0) != 6) {
            Py_DECREF(amp);
            PyErr_SetString(PyExc_ValueError, "ClosedIK: amplitude (6,) for the A-pair families");
            return -1;
        }
    }
    if (self->solver != NULL) { /* call() reads the design without the GIL: it never changes */
        PyErr_SetString(PyExc_TypeError, "ClosedIK: already initialised");
        return -1;
    }
    dh = (PyArrayObject *)PyArray_FROM_OTF(dh_obj, NPY_DOUBLE, NPY_ARRAY_IN_ARRAY);
    if (dh == NULL) {
        Py_XDECREF(amp);
        return -1;
    }
    if (PyArray_NDIM(dh) == 2 && PyArray_DIM(dh, 0) == 6 && PyArray_DIM(dh, 1) == 4 && scale > 0 && isfinite(scale) &&
        reach >= 0) {
        self->solver = (apair_ik_closed *)PyMem_Malloc(sizeof *self->solver);
        if (self->solver == NULL) {
            Py_DECREF(dh);
            PyErr_NoMemory();
            return -1;
        }
        const double *d = (const double *)PyArray_DATA(dh);
        if (family == GENERAL_6R) {
            if ((self->lapack = apair_native_lapack()) == NULL) {
                PyMem_Free(self->solver);
                self->solver = NULL;
                Py_DECREF(dh);
                return -1;
            }
            self->solver->family = GENERAL_6R;
            self->solver->scale = scale;
            memcpy(self->solver->dh, d, sizeof self->solver->dh);
        } else if (apairs ? apair_ik_closed_init_apair(self->solver, d, (const double *)PyArray_DATA(amp), scale) ||
                                self->solver->family != family
                          : apair_ik_closed_init(self->solver, family, d, scale)) {
            PyMem_Free(self->solver);
            self->solver = NULL;
        }
    }
    Py_DECREF(dh);
    Py_XDECREF(amp);
    if (self->solver == NULL) {
        PyErr_SetString(PyExc_ValueError, "ClosedIK: dh (6, 4) of a chain this closed form solves, scale > 0 and reach >= 0");
        return -1;
    }
    self->reach = reach;
    return 0;
}

static PyObject *closed_call(ClosedIKObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    double T[16], tol, q[6 * APAIR_IK_APAIR_MAX], error[APAIR_IK_APAIR_MAX];
    int found = 0, candidates = 0, flags = 0, rc;
    npy_intp dims[2];
    PyObject *qa, *ea;
    if (nargs != 2) {
        PyErr_SetString(PyExc_TypeError, "ClosedIK.call(T, tol)");
        return NULL;
    }
    if (self->solver == NULL) {
        PyErr_SetString(PyExc_RuntimeError, "ClosedIK: not initialised");
        return NULL;
    }
    if (!apair_native_enabled() || !apair_native_canonical(args[0], 2, 16, T) || !apair_native_rigid(T) || !PyFloat_Check(args[1]) ||
        !(T[3] * T[3] + T[7] * T[7] + T[11] * T[11] <= self->reach * self->reach)) {
        Py_RETURN_NONE;
    }
    tol = PyFloat_AS_DOUBLE(args[1]);
    if (!(tol > 0.0) || !isfinite(tol)) {
        Py_RETURN_NONE;
    }
    Py_BEGIN_ALLOW_THREADS
    if (self->solver->family == GENERAL_6R)
        rc = apair_ik6r(self->lapack, self->solver->dh, self->solver->scale, T, tol, q, error, &found, &candidates);
    else
        rc = apair_ik_closed_solve(self->solver, 1, T, 0, tol, q, error, &found, &candidates, &flags);
    Py_END_ALLOW_THREADS
    if (rc != 0 || flags < 0) {
        Py_RETURN_NONE;
    }
    dims[0] = found;
    dims[1] = 6;
    qa = PyArray_SimpleNew(2, dims, NPY_DOUBLE);
    ea = PyArray_SimpleNew(1, dims, NPY_DOUBLE);
    if (qa == NULL || ea == NULL) {
        Py_XDECREF(qa);
        Py_XDECREF(ea);
        return NULL;
    }
    memcpy(PyArray_DATA((PyArrayObject *)qa), q, sizeof(double) * 6 * (size_t)found);
    memcpy(PyArray_DATA((PyArrayObject *)ea), error, sizeof(double) * (size_t)found);
    return Py_BuildValue("NNii", qa, ea, candidates, flags);
}

static PyMethodDef closed_methods[] = {
    {"call", (PyCFunction)(void (*)(void))closed_call, METH_FASTCALL,
     "call(T, tol) -> (q, error, candidates, flags), or None when the inputs need the validating path."},
    {NULL, NULL, 0, NULL},
};

PyTypeObject apair_native_closed_ik_type = {
    PyVarObject_HEAD_INIT(NULL, 0)
    .tp_name = "apair._native.ClosedIK",
    .tp_basicsize = sizeof(ClosedIKObject),
    .tp_dealloc = (destructor)closed_dealloc,
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = "ClosedIK(family, dh, scale, reach, amplitude=None): the single-pose fast path of AChain.ik for chains "
              "solved in closed form (1: a spherical wrist, 2: axes 2, 3, 4 parallel, 3: axes 1, 2, 3 parallel with 5, 6 "
              "meeting, | 4 at the base end; 8 and 16: a UR-like chain with sinusoidal A-pairs of amplitudes amplitude "
              "(6,) at joint 3, or at joints 1 and 5; 32 and 64: a spherical wrist's with one at joint 3, or at joint 1; "
              "128: six R-pairs by the 6R elimination; apair.ik.solver).",
    .tp_methods = closed_methods,
    .tp_init = (initproc)closed_init,
    .tp_new = PyType_GenericNew,
};
