/*
 * apair._native: the Python binding of the generated C kernels (generated/c), generic over the
 * kernel registry (apair_kernels), so nothing here is written per kernel.
 *
 * call(index, *inputs) evaluates registry kernel `index` on float64 C-contiguous, aligned NumPy
 * arrays in native byte order whose trailing dimensions are the kernel's argument shapes. Leading
 * (batch) dimensions must be the same for every input that has them; an input without them is
 * shared by the whole batch (stride 0). Returns the list of output arrays, or None when some input
 * is not in that canonical form: the caller (apair.kernels) then converts and broadcasts, and calls
 * again. That keeps the common single-pose and batched calls free of Python-level array handling.
 * Large batches run without the GIL (the kernels are pure functions).
 *
 * Besides: Chain (one chain's methods in one native call), and the inverse-kinematics solvers of
 * apair_ik.c (ik_*), marshalled by one table-driven function (see "Inverse kinematics" below).
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#define NPY_NO_DEPRECATED_API NPY_1_7_API_VERSION
#include <numpy/arrayobject.h>

#include <math.h>
#include <string.h>

#include "apair.h"

#ifndef APAIR_SOURCES_HASH /* set by setup.py: the SHA-256 of the generated C files compiled */
#error "APAIR_SOURCES_HASH must be defined (build with setup.py)"
#endif

#define MAX_ARGS 16
#define MAX_DIMS NPY_MAXDIMS
#define NOGIL_COUNT 64 /* release the GIL from this batch size on */

static PyObject *native_call(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    const apair_kernel *k;
    const double *in[MAX_ARGS];
    double *out[MAX_ARGS];
    ptrdiff_t stride[MAX_ARGS];
    npy_intp batch[MAX_DIMS], dims[MAX_DIMS];
    int batch_nd = -1;
    size_t count = 1;
    long index;
    int i, d;
    PyObject *result;
    (void)self;

    if (nargs < 1) {
        PyErr_SetString(PyExc_TypeError, "call(index, *inputs): missing the kernel index");
        return NULL;
    }
    index = PyLong_AsLong(args[0]);
    if (index == -1 && PyErr_Occurred()) {
        return NULL;
    }
    if (index < 0 || index >= APAIR_KERNEL_COUNT) {
        PyErr_Format(PyExc_IndexError, "call: no kernel with index %ld", index);
        return NULL;
    }
    k = &apair_kernels[index];
    if (nargs - 1 != k->n_inputs) {
        PyErr_Format(PyExc_TypeError, "%s: expected %d inputs, got %zd", k->name, k->n_inputs, nargs - 1);
        return NULL;
    }
    if (k->n_inputs > MAX_ARGS || k->n_outputs > MAX_ARGS) {
        PyErr_Format(PyExc_RuntimeError, "%s: more than %d arguments", k->name, MAX_ARGS);
        return NULL;
    }
    for (i = 0; i < k->n_inputs; ++i) {
        PyArrayObject *a;
        const apair_arg *spec = &k->inputs[i];
        int nd, extra;
        if (!PyArray_Check(args[i + 1])) {
            Py_RETURN_NONE;
        }
        a = (PyArrayObject *)args[i + 1];
        nd = PyArray_NDIM(a);
        extra = nd - spec->rank;
        if (PyArray_TYPE(a) != NPY_DOUBLE || !PyArray_ISNOTSWAPPED(a) || !PyArray_IS_C_CONTIGUOUS(a) ||
            !PyArray_ISALIGNED(a) || extra < 0) {
            Py_RETURN_NONE;
        }
        for (d = 0; d < spec->rank; ++d) {
            if (PyArray_DIM(a, extra + d) != spec->shape[d]) {
                Py_RETURN_NONE;
            }
        }
        in[i] = (const double *)PyArray_DATA(a);
        if (extra == 0) {
            stride[i] = 0;
            continue;
        }
        if (batch_nd < 0) {
            batch_nd = extra;
            for (d = 0; d < extra; ++d) {
                batch[d] = PyArray_DIM(a, d);
                count *= (size_t)batch[d];
            }
        } else {
            if (extra != batch_nd) {
                Py_RETURN_NONE;
            }
            for (d = 0; d < extra; ++d) {
                if (PyArray_DIM(a, d) != batch[d]) {
                    Py_RETURN_NONE;
                }
            }
        }
        stride[i] = spec->size;
    }
    if (batch_nd < 0) {
        batch_nd = 0;
    }
    result = PyList_New(k->n_outputs);
    if (result == NULL) {
        return NULL;
    }
    for (i = 0; i < k->n_outputs; ++i) {
        const apair_arg *spec = &k->outputs[i];
        PyObject *o;
        if (batch_nd + spec->rank > MAX_DIMS) {
            Py_DECREF(result);
            PyErr_Format(PyExc_ValueError, "%s: too many batch dimensions", k->name);
            return NULL;
        }
        for (d = 0; d < batch_nd; ++d) {
            dims[d] = batch[d];
        }
        for (d = 0; d < spec->rank; ++d) {
            dims[batch_nd + d] = spec->shape[d];
        }
        o = PyArray_SimpleNew(batch_nd + spec->rank, dims, NPY_DOUBLE);
        if (o == NULL) {
            Py_DECREF(result);
            return NULL;
        }
        out[i] = (double *)PyArray_DATA((PyArrayObject *)o);
        PyList_SET_ITEM(result, i, o);
    }
    if (batch_nd == 0) {
        k->eval(in, out);
    } else if (count >= NOGIL_COUNT) {
        Py_BEGIN_ALLOW_THREADS
        k->eval_batch(count, in, stride, out);
        Py_END_ALLOW_THREADS
    } else if (count > 0) {
        k->eval_batch(count, in, stride, out);
    }
    return result;
}

static PyObject *native_names(PyObject *self, PyObject *unused)
{
    PyObject *names = PyTuple_New(APAIR_KERNEL_COUNT);
    int i;
    (void)self;
    (void)unused;
    if (names == NULL) {
        return NULL;
    }
    for (i = 0; i < APAIR_KERNEL_COUNT; ++i) {
        PyObject *s = PyUnicode_FromString(apair_kernels[i].name);
        if (s == NULL) {
            Py_DECREF(names);
            return NULL;
        }
        PyTuple_SET_ITEM(names, i, s);
    }
    return names;
}

/* ------------------------------------------------------------------------------------------------
 * Chain: the fast path of AChain's methods. One object per chain holds, per method, the kernel
 * that computes it (a generic chain kernel fed by the joints' law kernels, or a specialised kernel
 * of that chain taking q itself), the design arrays, and the joints' ranges. call(method, q, ...)
 * evaluates it in one native call when every input is already canonical (float64 arrays, native
 * byte order, C-contiguous, aligned, the same shape (..., n), finite, inside the joints' ranges) and
 * every output is finite. Otherwise it returns None and AChain takes its validating path, which
 * raises the ValueError that names the argument, or converts and broadcasts (so this file needs no
 * error messages of its own and cannot disagree with them).
 */
#define MAX_JOINTS 6
#define MAX_METHODS 16
#define MAX_DESIGN 8
#define CHAIN_BLOCK 512 /* items whose law values are formed before the chain kernel runs on them */

enum { SRC_LAW = -1, SRC_Q = -2, SRC_ARG1 = -3, SRC_ARG2 = -4 };

static int native_enabled = 0; /* set by apair.kernels once the C backend is chosen */

typedef struct {
    const apair_kernel *kernel; /* NULL: the method has no kernel here */
    int strict;                 /* needs every ranged joint strictly inside its range (d' finite) */
    int source[MAX_ARGS];       /* per kernel input: SRC_* or the index of a design array */
    double *inv;                /* the kernel's design invariants (its split form), or NULL */
} chain_method;

typedef struct {
    PyObject_HEAD
    int n;
    int n_methods;
    int uses_law;
    chain_method methods[MAX_METHODS];
    const apair_kernel *law[MAX_JOINTS];
    double law_params[MAX_JOINTS][2];
    double limit[MAX_JOINTS]; /* |theta| (mod 2 pi) range of each joint, INFINITY if unbounded */
    PyObject *design[MAX_DESIGN];
    int n_design;
    PyObject *keep; /* what must outlive the kernels (the loaded library of a specialised chain) */
} ChainObject;

static void chain_dealloc(ChainObject *self)
{
    int i;
    for (i = 0; i < self->n_methods; ++i) {
        PyMem_Free(self->methods[i].inv);
    }
    for (i = 0; i < self->n_design; ++i) {
        Py_XDECREF(self->design[i]);
    }
    Py_XDECREF(self->keep);
    Py_TYPE(self)->tp_free((PyObject *)self);
}

static const apair_kernel *kernel_at(PyObject *address)
{
    void *p = PyLong_AsVoidPtr(address);
    if (p == NULL && !PyErr_Occurred()) {
        PyErr_SetString(PyExc_ValueError, "Chain: a kernel address is NULL");
    }
    return (const apair_kernel *)p;
}

/* Chain(n, methods, laws, limits, design, keep): methods = [(kernel address or None, strict)],
 * laws = [(law kernel address, (params...))] per joint (empty when no method takes law values),
 * limits = per joint range (inf if none), design = {name: float64 array}, keep = any object. */
static int chain_init(ChainObject *self, PyObject *args, PyObject *kwds)
{
    PyObject *methods, *laws, *limits, *design, *keep;
    Py_ssize_t i, j;
    (void)kwds;
    if (!PyArg_ParseTuple(args, "iOOOOO", &self->n, &methods, &laws, &limits, &design, &keep)) {
        return -1;
    }
    if (self->n < 1 || self->n > MAX_JOINTS || !PyList_Check(methods) || !PyList_Check(laws) ||
        !PyList_Check(limits) || !PyDict_Check(design) || PyList_GET_SIZE(methods) > MAX_METHODS ||
        PyList_GET_SIZE(limits) != self->n || (PyList_GET_SIZE(laws) != 0 && PyList_GET_SIZE(laws) != self->n)) {
        PyErr_SetString(PyExc_ValueError, "Chain: malformed arguments");
        return -1;
    }
    Py_INCREF(keep);
    self->keep = keep;
    self->uses_law = PyList_GET_SIZE(laws) != 0;
    for (i = 0; i < self->n; ++i) {
        self->limit[i] = PyFloat_AsDouble(PyList_GET_ITEM(limits, i));
        if (PyErr_Occurred()) {
            return -1;
        }
    }
    for (i = 0; i < PyList_GET_SIZE(laws); ++i) {
        PyObject *item = PyList_GET_ITEM(laws, i), *params;
        if (!PyTuple_Check(item) || PyTuple_GET_SIZE(item) != 2 || !PyTuple_Check(PyTuple_GET_ITEM(item, 1))) {
            PyErr_SetString(PyExc_ValueError, "Chain: a law is (address, params)");
            return -1;
        }
        self->law[i] = kernel_at(PyTuple_GET_ITEM(item, 0));
        if (self->law[i] == NULL) {
            return -1;
        }
        params = PyTuple_GET_ITEM(item, 1);
        if (PyTuple_GET_SIZE(params) != self->law[i]->n_inputs - 1 || PyTuple_GET_SIZE(params) > 2) {
            PyErr_SetString(PyExc_ValueError, "Chain: wrong number of law parameters");
            return -1;
        }
        for (j = 0; j < PyTuple_GET_SIZE(params); ++j) {
            self->law_params[i][j] = PyFloat_AsDouble(PyTuple_GET_ITEM(params, j));
            if (PyErr_Occurred()) {
                return -1;
            }
        }
    }
    self->n_methods = (int)PyList_GET_SIZE(methods);
    for (i = 0; i < self->n_methods; ++i) {
        PyObject *item = PyList_GET_ITEM(methods, i);
        chain_method *m = &self->methods[i];
        if (!PyTuple_Check(item) || PyTuple_GET_SIZE(item) != 2) {
            PyErr_SetString(PyExc_ValueError, "Chain: a method is (address or None, strict)");
            return -1;
        }
        m->strict = PyObject_IsTrue(PyTuple_GET_ITEM(item, 1));
        if (PyTuple_GET_ITEM(item, 0) == Py_None) {
            m->kernel = NULL;
            continue;
        }
        m->kernel = kernel_at(PyTuple_GET_ITEM(item, 0));
        if (m->kernel == NULL) {
            return -1;
        }
        if (m->kernel->n_inputs > MAX_ARGS || m->kernel->n_outputs != 1) {
            PyErr_Format(PyExc_ValueError, "Chain: kernel %s does not fit", m->kernel->name);
            return -1;
        }
        for (j = 0; j < m->kernel->n_inputs; ++j) {
            const apair_arg *a = &m->kernel->inputs[j];
            const char *name = a->name;
            PyObject *arr;
            int d;
            if (strcmp(name, "law") == 0) {
                if (!self->uses_law) {
                    PyErr_Format(PyExc_ValueError, "Chain: %s takes law values but no laws were given", m->kernel->name);
                    return -1;
                }
                m->source[j] = SRC_LAW;
                continue;
            }
            if (strcmp(name, "q") == 0 || strcmp(name, "qd") == 0 || strcmp(name, "qdd") == 0 || strcmp(name, "tau") == 0) {
                if (a->rank != 1 || a->shape[0] != self->n) {
                    PyErr_Format(PyExc_ValueError, "Chain: %s input %s is not (n,)", m->kernel->name, name);
                    return -1;
                }
                m->source[j] = name[0] == 'q' && name[1] == '\0' ? SRC_Q : (strcmp(name, "qd") == 0 ? SRC_ARG1 : SRC_ARG2);
                continue;
            }
            arr = PyDict_GetItemString(design, name);
            if (arr == NULL || !PyArray_Check(arr) || PyArray_TYPE((PyArrayObject *)arr) != NPY_DOUBLE ||
                !PyArray_IS_C_CONTIGUOUS((PyArrayObject *)arr) || !PyArray_ISALIGNED((PyArrayObject *)arr) ||
                !PyArray_ISNOTSWAPPED((PyArrayObject *)arr) || PyArray_SIZE((PyArrayObject *)arr) != a->size) {
                PyErr_Format(PyExc_ValueError, "Chain: design input %s of %s is missing or malformed", name,
                             m->kernel->name);
                return -1;
            }
            for (d = 0; d < self->n_design; ++d) {
                if (self->design[d] == arr) {
                    break;
                }
            }
            if (d == self->n_design) {
                if (d == MAX_DESIGN) {
                    PyErr_SetString(PyExc_ValueError, "Chain: too many design inputs");
                    return -1;
                }
                Py_INCREF(arr);
                self->design[self->n_design++] = arr;
            }
            m->source[j] = d;
        }
        if (m->kernel->n_invariants > 0 && m->kernel->invariants != NULL && m->kernel->core != NULL) {
            /* the design never changes: its invariants once, here, and single items go to the core */
            const double *in[MAX_ARGS];
            m->inv = (double *)PyMem_Malloc(sizeof(double) * (size_t)m->kernel->n_invariants);
            if (m->inv == NULL) {
                PyErr_NoMemory();
                return -1;
            }
            for (j = 0; j < m->kernel->n_inputs; ++j) {
                in[j] = m->source[j] >= 0 ? (const double *)PyArray_DATA((PyArrayObject *)self->design[m->source[j]]) : NULL;
            }
            m->kernel->invariants(in, m->inv);
        }
    }
    return 0;
}

/* An argument in canonical form with the shape `like` (or any (..., n) when like is NULL). */
static int canonical(PyObject *o, PyArrayObject *like, int n)
{
    PyArrayObject *a;
    if (!PyArray_Check(o)) {
        return 0;
    }
    a = (PyArrayObject *)o;
    if (PyArray_TYPE(a) != NPY_DOUBLE || !PyArray_ISNOTSWAPPED(a) || !PyArray_IS_C_CONTIGUOUS(a) || !PyArray_ISALIGNED(a)) {
        return 0;
    }
    if (like == NULL) {
        return PyArray_NDIM(a) >= 1 && PyArray_NDIM(a) <= 24 && PyArray_DIM(a, PyArray_NDIM(a) - 1) == n;
    }
    return PyArray_NDIM(a) == PyArray_NDIM(like) &&
           PyArray_CompareLists(PyArray_DIMS(a), PyArray_DIMS(like), PyArray_NDIM(a));
}

static int all_finite(const double *x, size_t size)
{
    size_t i;
    double acc = 0.0;
    for (i = 0; i < size; ++i) {
        acc += x[i] * 0.0; /* NaN for NaN or inf, else 0 */
    }
    return acc == 0.0;
}

static int inside(const ChainObject *self, const double *q, size_t count, int strict)
{
    size_t k;
    int i;
    for (i = 0; i < self->n; ++i) {
        const double lim = self->limit[i];
        if (isinf(lim)) {
            continue;
        }
        for (k = 0; k < count; ++k) {
            const double th = q[k * (size_t)self->n + (size_t)i];
            const double t = fabs(th - 6.283185307179586 * nearbyint(th / 6.283185307179586));
            if (strict ? !(t < lim) : !(t <= lim)) {
                return 0;
            }
        }
    }
    return 1;
}

/* The law values of `count` items of q into law[count][n][5]. */
static void fill_law(const ChainObject *self, const double *q, size_t count, double *law)
{
    size_t k;
    int i;
    for (k = 0; k < count; ++k) {
        for (i = 0; i < self->n; ++i) {
            const double *in[3];
            double *out[1];
            in[0] = q + k * (size_t)self->n + (size_t)i;
            in[1] = &self->law_params[i][0];
            in[2] = &self->law_params[i][1];
            out[0] = law + (k * (size_t)self->n + (size_t)i) * 5;
            self->law[i]->eval(in, out);
        }
    }
}

static PyObject *chain_call(ChainObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    const chain_method *m;
    const apair_kernel *k;
    PyArrayObject *q, *out;
    const double *given[3];
    const double *in[MAX_ARGS];
    double *outp[1];
    ptrdiff_t stride[MAX_ARGS];
    npy_intp dims[MAX_DIMS];
    double law_one[MAX_JOINTS * 5];
    double *law = law_one;
    size_t count, size, done;
    PyThreadState *released = NULL;
    long method;
    int i, nd, ok = 1;

    if (nargs < 2 || nargs > 4) {
        PyErr_SetString(PyExc_TypeError, "Chain.call(method, q[, a[, b]])");
        return NULL;
    }
    method = PyLong_AsLong(args[0]);
    if (method == -1 && PyErr_Occurred()) {
        return NULL;
    }
    if (method < 0 || method >= self->n_methods) {
        PyErr_Format(PyExc_IndexError, "Chain.call: no method %ld", method);
        return NULL;
    }
    m = &self->methods[method];
    k = m->kernel;
    if (!native_enabled || k == NULL || !canonical(args[1], NULL, self->n)) {
        Py_RETURN_NONE;
    }
    q = (PyArrayObject *)args[1];
    given[0] = (const double *)PyArray_DATA(q);
    for (i = 2; i < nargs; ++i) {
        if (!canonical(args[i], q, self->n)) {
            Py_RETURN_NONE;
        }
        given[i - 1] = (const double *)PyArray_DATA((PyArrayObject *)args[i]);
    }
    size = (size_t)PyArray_SIZE(q);
    count = size / (size_t)self->n;
    for (i = 0; i < nargs - 1; ++i) {
        if (!all_finite(given[i], size)) {
            Py_RETURN_NONE;
        }
    }
    if (!inside(self, given[0], count, m->strict)) {
        Py_RETURN_NONE;
    }
    for (i = 0; i < k->n_inputs; ++i) {
        const int s = m->source[i];
        if ((s == SRC_ARG1 && nargs < 3) || (s == SRC_ARG2 && nargs < 4)) {
            PyErr_Format(PyExc_TypeError, "Chain.call: %s needs more inputs", k->name);
            return NULL;
        }
    }
    nd = PyArray_NDIM(q) - 1;
    if (nd + k->outputs[0].rank > MAX_DIMS) {
        Py_RETURN_NONE;
    }
    for (i = 0; i < nd; ++i) {
        dims[i] = PyArray_DIM(q, i);
    }
    for (i = 0; i < k->outputs[0].rank; ++i) {
        dims[nd + i] = k->outputs[0].shape[i];
    }
    out = (PyArrayObject *)PyArray_SimpleNew(nd + k->outputs[0].rank, dims, NPY_DOUBLE);
    if (out == NULL) {
        return NULL;
    }
    outp[0] = (double *)PyArray_DATA(out);
    if (count > 1 && self->uses_law) {
        law = (double *)PyMem_RawMalloc(sizeof(double) * 5 * (size_t)self->n * (count < CHAIN_BLOCK ? count : CHAIN_BLOCK));
        if (law == NULL) {
            Py_DECREF(out);
            return PyErr_NoMemory();
        }
    }
    if (count >= NOGIL_COUNT) {
        released = PyEval_SaveThread();
    }
    for (done = 0; done < count;) {
        const size_t m_items = count - done < CHAIN_BLOCK ? count - done : CHAIN_BLOCK;
        for (i = 0; i < k->n_inputs; ++i) {
            const int s = m->source[i];
            const size_t stride_items = (size_t)k->inputs[i].size;
            if (s == SRC_LAW) {
                in[i] = law;
                stride[i] = (ptrdiff_t)stride_items;
            } else if (s <= SRC_Q) {
                in[i] = given[SRC_Q - s] + done * (size_t)self->n;
                stride[i] = (ptrdiff_t)stride_items;
            } else {
                in[i] = (const double *)PyArray_DATA((PyArrayObject *)self->design[s]);
                stride[i] = 0;
            }
        }
        if (self->uses_law) {
            fill_law(self, given[0] + done * (size_t)self->n, m_items, law);
        }
        if (count == 1 && m->inv != NULL) {
            k->core(m->inv, in, outp);
        } else if (count == 1) {
            k->eval(in, outp);
        } else {
            double *o[1];
            o[0] = outp[0] + done * (size_t)k->outputs[0].size;
            k->eval_batch(m_items, in, stride, o);
        }
        done += m_items;
    }
    ok = all_finite(outp[0], count * (size_t)k->outputs[0].size);
    if (released != NULL) {
        PyEval_RestoreThread(released);
    }
    if (law != law_one) {
        PyMem_RawFree(law);
    }
    if (!ok) {
        Py_DECREF(out);
        Py_RETURN_NONE;
    }
    return (PyObject *)out;
}

static PyMethodDef chain_methods[] = {
    {"call", (PyCFunction)(void (*)(void))chain_call, METH_FASTCALL,
     "call(method, q[, a[, b]]) -> the method's output, or None when the inputs need the validating path."},
    {NULL, NULL, 0, NULL},
};

static PyTypeObject ChainType = {
    PyVarObject_HEAD_INIT(NULL, 0)
    .tp_name = "apair._native.Chain",
    .tp_basicsize = sizeof(ChainObject),
    .tp_dealloc = (destructor)chain_dealloc,
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = "The native fast path of one chain's methods (see apair.kernels.native_chain).",
    .tp_methods = chain_methods,
    .tp_init = (initproc)chain_init,
    .tp_new = PyType_GenericNew,
};

static PyObject *native_enable(PyObject *self, PyObject *flag)
{
    (void)self;
    native_enabled = PyObject_IsTrue(flag) == 1;
    Py_RETURN_NONE;
}

static PyObject *native_kernel_address(PyObject *self, PyObject *index)
{
    long i = PyLong_AsLong(index);
    (void)self;
    if (i == -1 && PyErr_Occurred()) {
        return NULL;
    }
    if (i < 0 || i >= APAIR_KERNEL_COUNT) {
        PyErr_Format(PyExc_IndexError, "kernel_address: no kernel with index %ld", i);
        return NULL;
    }
    return PyLong_FromVoidPtr((void *)&apair_kernels[i]);
}

/* ------------------------------------------------------------------------------------------------
 * Inverse kinematics: the entry points of apair_ik.c, one row each of the table ik_entries, all
 * marshalled by ik_marshal. A row gives the positional arguments in PyArg_ParseTuple's letters ('O'
 * an array; 'd', 'i', 'D', 'p' a float, int, complex, bool; optional ones after '|'), each array's
 * name, NumPy type and shape (it is converted to a C-contiguous array of that type, then checked),
 * the outputs likewise, and an adapter that calls the C function on the converted pointers. Sizes
 * are numbers, ANY, N (the first argument's length) or ROWS (the length of argument `rows`: the C
 * function's count); `prepare` checks what the shapes cannot say and sets the outputs' shapes they
 * do not give. The adapter runs without the GIL where `nogil`; it returns 0 (the call returns the
 * one output, or the tuple of them), > 0 (None) or < 0 (ValueError(error)).
 */
#define IK_MAX_ARGS 12 /* letters of a format, at most */
#define IK_MAX_OUT 8

enum { ANY = -1, N = -2, ROWS = -3 };
enum { I32 = NPY_INT32, F64 = NPY_DOUBLE, C128 = NPY_CDOUBLE };

typedef struct {
    const char *name;
    int type, nd;
    npy_intp shape[3];
} ik_array;

typedef struct {
    Py_ssize_t given;              /* positional arguments given */
    npy_intp n;                    /* the first argument's length */
    size_t rows;                   /* the length of argument `rows` */
    PyArrayObject *a[IK_MAX_ARGS]; /* per argument: the array, or NULL */
    union {
        double d;
        int i;
        Py_complex z;
    } s[IK_MAX_ARGS];              /* per argument: the scalar */
    PyArrayObject *o[IK_MAX_OUT];  /* the outputs */
    npy_intp dims[IK_MAX_OUT][3];  /* their shapes */
} ik_call;

typedef struct {
    const char *format;
    ik_array arrays[IK_MAX_ARGS]; /* the 'O' arguments, in order */
    ik_array out[IK_MAX_OUT];     /* the outputs, up to the first without a name */
    int rows, nogil;
    int (*prepare)(ik_call *c);   /* NULL, or 0 / -1 with an error set */
    int (*run)(const ik_call *c);
    const char *error;
} ik_entry;

static const void *in(const ik_call *c, int j) { return PyArray_DATA(c->a[j]); }
static void *out(const ik_call *c, int k) { return PyArray_DATA(c->o[k]); }
static int len(const ik_call *c, int j, int d) { return (int)PyArray_DIM(c->a[j], d); }

static int check_shape(PyArrayObject *a, int nd, const npy_intp *shape, const char *what)
{
    if (PyArray_NDIM(a) != nd) {
        PyErr_Format(PyExc_ValueError, "%s: expected %d dimensions", what, nd);
        return -1;
    }
    for (int d = 0; d < nd; d++) {
        if (shape[d] >= 0 && PyArray_DIM(a, d) != shape[d]) {
            PyErr_Format(PyExc_ValueError, "%s: dimension %d is %zd, expected %zd", what, d,
                         (Py_ssize_t)PyArray_DIM(a, d), (Py_ssize_t)shape[d]);
            return -1;
        }
    }
    return 0;
}

/* ---- the adapters, and what the shapes cannot say (argument numbers as in the format) */

static int run_track(const ik_call *c)
{
    apair_ik_problem pb = {6, in(c, 0), in(c, 1), in(c, 2)};
    apair_ik_options opt;
    double gamma[2] = {c->s[5].z.real, c->s[5].z.imag};
    apair_ik_default_options(&opt);
    opt.wide_track = c->given > 7 ? c->s[7].d : opt.wide_track;
    opt.wide_end = c->given > 8 ? c->s[8].d : opt.wide_end;
    opt.wide_steps = c->given > 9 ? c->s[9].i : opt.wide_steps;
    return apair_ik_track(&pb, &opt, in(c, 3), in(c, 4), gamma, c->rows, in(c, 6), out(c, 0), out(c, 1), out(c, 2),
                          out(c, 3));
}

static int run_track_slice(const ik_call *c)
{
    apair_ik_problem pb = {6, in(c, 0), in(c, 1), in(c, 2)};
    apair_ik_options opt;
    apair_ik_slice sl = {.t0 = {c->s[7].z.real, c->s[7].z.imag}, .dt = {c->s[8].z.real, c->s[8].z.imag},
                         .times_lambda = c->s[9].i};
    double gamma[2] = {c->s[10].z.real, c->s[10].z.imag};
    apair_ik_default_options(&opt);
    memcpy(sl.p, in(c, 3), sizeof sl.p);
    memcpy(sl.w, in(c, 4), sizeof sl.w);
    memcpy(sl.ell, in(c, 5), sizeof sl.ell);
    memcpy(sl.dell, in(c, 6), sizeof sl.dell);
    return apair_ik_track_slice(&pb, &opt, &sl, gamma, c->rows, in(c, 11), out(c, 0), out(c, 1), out(c, 2), out(c, 3));
}

static int run_ik6r_angles(const ik_call *c)
{
    return apair_ik6r_angles(c->rows, in(c, 0), in(c, 1), in(c, 2), in(c, 3), in(c, 4), in(c, 5), in(c, 6), out(c, 0));
}

static int run_newton(const ik_call *c)
{
    apair_ik_problem pb = {6, in(c, 0), in(c, 1), in(c, 2)};
    memcpy(out(c, 0), in(c, 4), (size_t)PyArray_NBYTES(c->a[4])); /* theta, updated in place */
    return apair_ik_newton(&pb, in(c, 3), c->rows, out(c, 0), c->s[5].i, c->s[6].d, c->s[7].d, c->s[8].d, c->s[9].d,
                           out(c, 1));
}

static int prepare_local(ik_call *c)
{
    if (PyArray_DIM(c->a[6], 0) != (npy_intp)c->rows && PyArray_DIM(c->a[6], 0) != 1) {
        PyErr_SetString(PyExc_ValueError, "target: one pose, or one per seed");
        return -1;
    }
    return 0;
}

static int run_local(const ik_call *c)
{
    apair_ik_chain ch = {(int)c->n, in(c, 0), in(c, 1), in(c, 2), in(c, 3), in(c, 4), c->s[5].d};
    ptrdiff_t tstride = PyArray_DIM(c->a[6], 0) == 1 ? 0 : 16;
    return apair_ik_local(&ch, c->rows, in(c, 6), tstride, in(c, 7), (ptrdiff_t)c->n, c->s[8].d, c->s[9].i, out(c, 0),
                          out(c, 1), out(c, 2));
}

/* f: (2 d3 - 2 af[0] + 1, 2 d4 - 2 af[1] + 1), g: the same of ag, deflated (see apair_ik4_pencil), M: square */
static int prepare_pencil(ik_call *c)
{
    const int d[2] = {len(c, 0, 0) - 1, len(c, 0, 1) - 1}, *af = in(c, 2), *ag = in(c, 4);
    npy_intp *f = c->dims[0], *g = c->dims[1];
    for (int i = 0; i < 2; i++) {
        f[i] = 2 * d[i] - 2 * af[i] + 1;
        g[i] = 2 * d[i] - 2 * ag[i] + 1;
        if (c->s[6].i & (1 << i)) { /* deflate: (g - a f) / (1 + u^2), degree max(G, F + 1) - 2 in u3 (u4) */
            g[i] = (g[i] > f[i] + 1 ? g[i] : f[i] + 1) - 2;
        }
    }
    if (f[0] < 2 || f[1] < 1 || g[0] < 2 || g[1] < 1) {
        PyErr_SetString(PyExc_ValueError, "ik4_pencil: the factors leave an image constant in u3");
        return -1;
    }
    c->dims[2][0] = c->dims[2][1] = (g[1] - 1) * (f[0] - 1) + (f[1] - 1) * (g[0] - 1);
    return 0;
}

static int run_pencil(const ik_call *c)
{
    int size = 0;
    return apair_ik4_pencil(len(c, 0, 0) - 1, len(c, 0, 1) - 1, in(c, 0), in(c, 1), in(c, 2), in(c, 3), in(c, 4),
                            c->s[5].d, c->s[6].i, c->s[7].d, out(c, 0), out(c, 1), out(c, 2), &size);
}

static int prepare_screen(ik_call *c)
{
    const npy_intp probe[1] = {(npy_intp)len(c, 2, 1) + len(c, 3, 1) - 2}; /* F1 + G1 */
    return check_shape(c->a[5], 1, probe, "probe");
}

static int run_screen(const ik_call *c)
{
    return apair_ik4_screen(c->rows, in(c, 0), len(c, 1, 0) - 1, len(c, 1, 1) - 1, in(c, 1), in(c, 2), len(c, 2, 0) - 1,
                            len(c, 2, 1) - 1, in(c, 3), len(c, 3, 0) - 1, len(c, 3, 1) - 1, len(c, 4, 0), in(c, 4),
                            in(c, 5), in(c, 6), out(c, 0), out(c, 1), out(c, 2), out(c, 3), out(c, 4), out(c, 5),
                            out(c, 6), out(c, 7));
}

static int run_left(const ik_call *c)
{
    return apair_ik4_left(c->rows, in(c, 0), len(c, 1, 0) - 1, in(c, 1), len(c, 2, 0) - 1, in(c, 2), in(c, 3), in(c, 4),
                          out(c, 0), out(c, 1), out(c, 2), out(c, 3));
}

/* ---- the table */

enum { IK_TRACK, IK_TRACK_SLICE, IK6R_ANGLES, IK_NEWTON, IK_LOCAL, IK4_PENCIL, IK4_SCREEN, IK4_LEFT };

static const ik_entry ik_entries[] = {
    [IK_TRACK] = {
        .format = "OOOOODO|ddi", /* kind, pair, dh, p0, p1, gamma, start[, wide_track, wide_end, wide_steps] */
        .arrays = {{"kind", I32, 1, {6}}, {"pair", F64, 2, {6, 2}}, {"dh", F64, 2, {6, 4}}, {"p0", C128, 1, {7}},
                   {"p1", C128, 1, {7}}, {"start", C128, 2, {ANY, 6}}},
        .out = {{"end", C128, 2, {ROWS, 6}}, {"status", I32, 1, {ROWS}}, {"steps", I32, 1, {ROWS}},
                {"cond", F64, 1, {ROWS}}},
        .rows = 6, .nogil = 1, .run = run_track,
        .error = "ik_track: the problem is not valid (kinds 0 or 1, 6 joints)",
    },
    [IK_TRACK_SLICE] = {
        .format = "OOOOOOODDpDO", /* kind, pair, dh, p, w, ell, dell, t0, dt, times_lambda, gamma, start */
        .arrays = {{"kind", I32, 1, {6}}, {"pair", F64, 2, {6, 2}}, {"dh", F64, 2, {6, 4}}, {"p", C128, 1, {7}},
                   {"w", C128, 1, {7}}, {"ell", C128, 2, {2, 6}}, {"dell", C128, 2, {2, 6}},
                   {"start", C128, 2, {ANY, 7}}},
        .out = {{"end", C128, 2, {ROWS, 7}}, {"status", I32, 1, {ROWS}}, {"steps", I32, 1, {ROWS}},
                {"cond", F64, 1, {ROWS}}},
        .rows = 11, .nogil = 1, .run = run_track_slice,
        .error = "ik_track_slice: the problem is not valid (kinds 0 or 1, 6 joints)",
    },
    [IK6R_ANGLES] = {
        .format = "OOOOOOO",
        .arrays = {{"x3", C128, 1, {ANY}}, {"vec", C128, 2, {N, 24}}, {"P", F64, 2, {14, 27}}, {"L", F64, 2, {14, 8}},
                   {"sigma", F64, 1, {3}}, {"dh", F64, 2, {6, 4}}, {"T", F64, 2, {4, 4}}},
        .out = {{"theta", C128, 2, {ROWS, 6}}},
        .run = run_ik6r_angles, .error = "ik6r_angles: failed",
    },
    [IK_NEWTON] = {
        .format = "OOOOOidddd", /* kind, pair, dh, p, theta, max_steps, tol, floor, stall, imag_max */
        .arrays = {{"kind", I32, 1, {6}}, {"pair", F64, 2, {6, 2}}, {"dh", F64, 2, {6, 4}}, {"p", C128, 1, {7}},
                   {"theta", C128, 2, {ANY, 6}}},
        .out = {{"theta", C128, 2, {ROWS, 6}}, {"size", F64, 1, {ROWS}}},
        .rows = 4, .nogil = 1, .run = run_newton,
        .error = "ik_newton: the problem is not valid (kinds 0 or 1, 6 joints)",
    },
    [IK_LOCAL] = {
        .format = "OOOOOdOOdi", /* kind, pair, dh, lower, upper, scale, target, seed, tol, max_iter */
        .arrays = {{"kind", I32, 1, {ANY}}, {"pair", F64, 2, {N, 2}}, {"dh", F64, 2, {N, 4}}, {"lower", F64, 1, {N}},
                   {"upper", F64, 1, {N}}, {"target", F64, 3, {ANY, 4, 4}}, {"seed", F64, 2, {ANY, N}}},
        .out = {{"q", F64, 2, {ROWS, N}}, {"residual", F64, 1, {ROWS}}, {"converged", I32, 1, {ROWS}}},
        .rows = 7, .nogil = 1, .prepare = prepare_local, .run = run_local,
        .error = "ik_local: the chain is not valid (kinds 0, 1 or 2; 1 to 6 joints)",
    },
    [IK4_PENCIL] = {
        .format = "OOOOOdid", /* C, Qf, af, Qg, ag, cond_max, deflate, deflate_tol */
        .arrays = {{"C", F64, 3, {ANY, ANY, 8}}, {"Qf", F64, 2, {8, 8}}, {"af", I32, 1, {2}}, {"Qg", F64, 2, {8, 8}},
                   {"ag", I32, 1, {2}}},
        .out = {{"f", F64, 2, {ANY, ANY}}, {"g", F64, 2, {ANY, ANY}}, {"M", F64, 2, {ANY, ANY}}},
        .prepare = prepare_pencil, .run = run_pencil, .error = "ik4_pencil: degrees out of range",
    },
    [IK4_SCREEN] = {
        .format = "OOOOOOO",
        .arrays = {{"u3", F64, 1, {ANY}}, {"C", F64, 3, {ANY, ANY, 8}}, {"f", F64, 2, {ANY, ANY}},
                   {"g", F64, 2, {ANY, ANY}}, {"Q", F64, 3, {ANY, 8, 8}}, {"probe", F64, 1, {ANY}},
                   {"tol", F64, 1, {3}}},
        .out = {{"status", I32, 1, {ROWS}}, {"u4", F64, 1, {ROWS}}, {"W", F64, 2, {ROWS, 8}}, {"rel", F64, 1, {ROWS}},
                {"two", F64, 3, {ROWS, 2, 2}}, {"two_ok", I32, 2, {ROWS, 2}}, {"W2", F64, 3, {ROWS, 2, 8}},
                {"rel2", F64, 2, {ROWS, 2}}},
        .prepare = prepare_screen, .run = run_screen, .error = "ik4_screen: the Sylvester size is out of range",
    },
    [IK4_LEFT] = {
        .format = "OOOOO",
        .arrays = {{"W", F64, 2, {ANY, 8}}, {"Zmap", F64, 3, {ANY, 8, 8}}, {"P2", F64, 2, {ANY, 8}},
                   {"joint", F64, 1, {4}}, {"tol", F64, 1, {4}}},
        .out = {{"status", I32, 1, {ROWS}}, {"u1", F64, 1, {ROWS}}, {"u2", F64, 2, {ROWS, 2}},
                {"ok", I32, 2, {ROWS, 2}}},
        .run = run_left, .error = "ik4_left: degrees out of range",
    },
};

/* ---- the marshaller */

/* Scalar argument j as PyArg_ParseTuple converts it (the same errors): 0, or -1. */
static int ik_scalar(ik_call *c, int j, char code, PyObject *obj)
{
    long v;
    switch (code) {
    case 'd':
        return (c->s[j].d = PyFloat_AsDouble(obj)) == -1.0 && PyErr_Occurred() ? -1 : 0;
    case 'D':
        c->s[j].z = PyComplex_AsCComplex(obj);
        return PyErr_Occurred() ? -1 : 0;
    case 'p':
        return (c->s[j].i = PyObject_IsTrue(obj)) < 0 ? -1 : 0;
    default: /* 'i' */
        v = PyLong_AsLong(obj);
        if (v > INT_MAX || v < INT_MIN) {
            PyErr_SetString(PyExc_OverflowError, v > INT_MAX ? "signed integer is greater than maximum"
                                                             : "signed integer is less than minimum");
        }
        c->s[j].i = (int)v;
        return PyErr_Occurred() ? -1 : 0;
    }
}

/* Array argument j converted to spec and its shape checked: 0, or -1 with an error. */
static int ik_convert(ik_call *c, int j, const ik_array *spec, PyObject *obj)
{
    npy_intp shape[3];
    for (int d = 0; d < spec->nd; d++) {
        shape[d] = spec->shape[d] == N ? c->n : spec->shape[d];
    }
    c->a[j] = (PyArrayObject *)PyArray_FROM_OTF(obj, spec->type, NPY_ARRAY_IN_ARRAY);
    return c->a[j] == NULL || check_shape(c->a[j], spec->nd, shape, spec->name) ? -1 : 0;
}

static PyObject *ik_marshal(PyObject *module, int entry, PyObject *tuple)
{
    PyObject *const *args = PySequence_Fast_ITEMS(tuple);
    const Py_ssize_t nargs = PyTuple_GET_SIZE(tuple);
    const ik_entry *e = &ik_entries[entry];
    ik_call c = {.given = nargs};
    char code[IK_MAX_ARGS];
    Py_ssize_t n_args = 0, n_required = -1;
    PyObject *outs = NULL, *result = NULL;
    int j, k, n_out, rc;
    (void)module;
    for (const char *f = e->format; *f; f++) {
        if (*f == '|') {
            n_required = n_args;
        } else {
            code[n_args++] = *f;
        }
    }
    n_required = n_required < 0 ? n_args : n_required;
    if (nargs < n_required || nargs > n_args) { /* PyArg_ParseTuple's message */
        PyErr_Format(PyExc_TypeError, "function takes %s %zd arguments (%zd given)",
                     n_required == n_args ? "exactly" : nargs < n_required ? "at least" : "at most",
                     nargs < n_required ? n_required : n_args, nargs);
        return NULL;
    }
    for (j = 0; j < nargs; j++) {
        if (code[j] != 'O' && ik_scalar(&c, j, code[j], args[j])) {
            return NULL;
        }
    }
    for (j = 0, k = 0; j < nargs; j++) {
        if (code[j] == 'O' && ik_convert(&c, j, &e->arrays[k++], args[j])) {
            goto done;
        }
        c.n = j == 0 ? PyArray_DIM(c.a[0], 0) : c.n;
        c.rows = j == e->rows ? (size_t)PyArray_DIM(c.a[j], 0) : c.rows;
    }
    for (n_out = 0; n_out < IK_MAX_OUT && e->out[n_out].name != NULL; n_out++) {
        for (int d = 0; d < e->out[n_out].nd; d++) {
            const npy_intp s = e->out[n_out].shape[d];
            c.dims[n_out][d] = s == N ? c.n : s == ROWS ? (npy_intp)c.rows : s;
        }
    }
    if ((e->prepare != NULL && e->prepare(&c)) || (outs = PyTuple_New(n_out)) == NULL) {
        goto done;
    }
    for (k = 0; k < n_out; k++) {
        if ((c.o[k] = (PyArrayObject *)PyArray_SimpleNew(e->out[k].nd, c.dims[k], e->out[k].type)) == NULL) {
            goto done;
        }
        PyTuple_SET_ITEM(outs, k, (PyObject *)c.o[k]);
    }
    if (e->nogil) {
        Py_BEGIN_ALLOW_THREADS
        rc = e->run(&c);
        Py_END_ALLOW_THREADS
    } else {
        rc = e->run(&c);
    }
    if (rc < 0) {
        PyErr_SetString(PyExc_ValueError, e->error);
    } else {
        result = rc > 0 ? Py_None : n_out == 1 ? (PyObject *)c.o[0] : outs;
        Py_INCREF(result);
    }
done:
    Py_XDECREF(outs);
    for (j = 0; j < nargs; j++) {
        Py_XDECREF(c.a[j]);
    }
    return result;
}

static PyObject *ik_track(PyObject *m, PyObject *args) { return ik_marshal(m, IK_TRACK, args); }
static PyObject *ik_track_slice(PyObject *m, PyObject *args) { return ik_marshal(m, IK_TRACK_SLICE, args); }
static PyObject *ik6r_angles(PyObject *m, PyObject *args) { return ik_marshal(m, IK6R_ANGLES, args); }
static PyObject *ik_newton(PyObject *m, PyObject *args) { return ik_marshal(m, IK_NEWTON, args); }
static PyObject *ik_local(PyObject *m, PyObject *args) { return ik_marshal(m, IK_LOCAL, args); }
static PyObject *ik4_pencil(PyObject *m, PyObject *args) { return ik_marshal(m, IK4_PENCIL, args); }
static PyObject *ik4_screen(PyObject *m, PyObject *args) { return ik_marshal(m, IK4_SCREEN, args); }
static PyObject *ik4_left(PyObject *m, PyObject *args) { return ik_marshal(m, IK4_LEFT, args); }

static PyMethodDef native_methods[] = {
    {"call", (PyCFunction)(void (*)(void))native_call, METH_FASTCALL,
     "call(index, *inputs) -> list of outputs, or None if an input needs converting first."},
    {"names", native_names, METH_NOARGS, "names() -> the kernel names, in registry (index) order."},
    {"enable", native_enable, METH_O, "enable(flag): whether Chain.call may evaluate (the C backend is in use)."},
    {"kernel_address", native_kernel_address, METH_O, "kernel_address(index) -> address of the registry entry."},
    {"ik_track_slice", ik_track_slice, METH_VARARGS,
     "ik_track_slice(kind, pair, dh, p, w, ell, dell, t0, dt, times_lambda, gamma, start) -> (end, status, steps, cond): "
     "apair_ik_track_slice."},
    {"ik_track", ik_track, METH_VARARGS,
     "ik_track(kind, pair, dh, p0, p1, gamma, start) -> (end, status, steps, cond): apair_ik_track."},
    {"ik6r_angles", ik6r_angles, METH_VARARGS,
     "ik6r_angles(x3, vec, P, L, sigma, dh, T) -> theta: apair_ik6r_angles."},
    {"ik_newton", ik_newton, METH_VARARGS,
     "ik_newton(kind, pair, dh, p, theta, max_steps, tol, floor, stall, imag_max) -> (theta, size): apair_ik_newton."},
    {"ik4_pencil", ik4_pencil, METH_VARARGS,
     "ik4_pencil(C, Qf, af, Qg, ag, cond_max, deflate, deflate_tol) -> (f, g, M) or None: apair_ik4_pencil."},
    {"ik4_screen", ik4_screen, METH_VARARGS,
     "ik4_screen(u3, C, f, g, Q, probe, tol) -> (status, u4, W, rel, two, two_ok, W2, rel2): apair_ik4_screen."},
    {"ik4_left", ik4_left, METH_VARARGS,
     "ik4_left(W, Zmap, P2, joint, tol) -> (status, u1, u2, ok): apair_ik4_left."},
    {"ik_local", ik_local, METH_VARARGS,
     "ik_local(kind, pair, dh, lower, upper, scale, target, seed, tol, max_iter) -> (q, residual, converged)."},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef native_module = {
    PyModuleDef_HEAD_INIT, "apair._native", "The generated C kernels, called from Python.", -1, native_methods,
    NULL, NULL, NULL, NULL,
};

PyMODINIT_FUNC PyInit__native(void)
{
    PyObject *m;
    import_array();
    if (PyType_Ready(&ChainType) < 0) {
        return NULL;
    }
    m = PyModule_Create(&native_module);
    if (m == NULL) {
        return NULL;
    }
    Py_INCREF(&ChainType);
    if (PyModule_AddObject(m, "Chain", (PyObject *)&ChainType) < 0 ||
        PyModule_AddIntConstant(m, "KERNEL_SIZE", (long)sizeof(apair_kernel)) < 0) {
        Py_DECREF(&ChainType);
        Py_DECREF(m);
        return NULL;
    }
    if (PyModule_AddStringConstant(m, "content_hash", APAIR_CONTENT_HASH) < 0 ||
        PyModule_AddStringConstant(m, "sources_hash", APAIR_SOURCES_HASH) < 0) {
        Py_DECREF(m);
        return NULL;
    }
    return m;
}
