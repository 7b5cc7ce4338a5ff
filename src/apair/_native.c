/*
 * apair._native: the Python binding of the generated C kernels (generated/c), generic over the
 * kernel registry (apair_kernels), so nothing here is written per kernel.
 *
 * call(index, *inputs) evaluates registry kernel `index` on float64 C-contiguous, aligned NumPy
 * arrays in native byte order * whose trailing dimensions are the kernel's argument shapes. Leading (batch) dimensions must be
 * the same for every input that has them; an input without them is shared by the whole batch
 * (stride 0). Returns the list of output arrays, or None when some input is not in that canonical
 * form: the caller (apair.kernels) then converts and broadcasts, and calls again. That keeps the
 * common single-pose and batched calls free of Python-level array handling. Large batches run
 * without the GIL (the kernels are pure functions).
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

/* ------------------------------------------------------------------ inverse kinematics */

static PyArrayObject *ik_array(PyObject *obj, int type, int nd, const npy_intp *shape, const char *what)
{
    PyArrayObject *a = (PyArrayObject *)PyArray_FROM_OTF(obj, type, NPY_ARRAY_IN_ARRAY);
    if (a == NULL) {
        return NULL;
    }
    if (PyArray_NDIM(a) != nd) {
        PyErr_Format(PyExc_ValueError, "%s: expected %d dimensions", what, nd);
        Py_DECREF(a);
        return NULL;
    }
    for (int d = 0; d < nd; d++) {
        if (shape[d] >= 0 && PyArray_DIM(a, d) != shape[d]) {
            PyErr_Format(PyExc_ValueError, "%s: dimension %d is %zd, expected %zd", what, d,
                         (Py_ssize_t)PyArray_DIM(a, d), (Py_ssize_t)shape[d]);
            Py_DECREF(a);
            return NULL;
        }
    }
    return a;
}

/* The trackers' outputs for s_out[0] paths of s_out[1] variables: end (complex), status, steps
 * (int32) and cond. 0, or -1 with a Python error set. */
static int track_outputs(const npy_intp *s_out, PyArrayObject **out)
{
    out[0] = (PyArrayObject *)PyArray_SimpleNew(2, s_out, NPY_CDOUBLE);
    out[1] = (PyArrayObject *)PyArray_SimpleNew(1, s_out, NPY_INT32);
    out[2] = (PyArrayObject *)PyArray_SimpleNew(1, s_out, NPY_INT32);
    out[3] = (PyArrayObject *)PyArray_SimpleNew(1, s_out, NPY_DOUBLE);
    if (out[0] && out[1] && out[2] && out[3]) return 0;
    for (int i = 0; i < 4; i++) Py_XDECREF(out[i]);
    return -1;
}

/* (end, status, steps, cond) of a tracker that returned rc, or NULL with an error (the outputs freed). */
static PyObject *track_result(int rc, PyArrayObject **out, const char *what)
{
    if (rc) {
        PyErr_Format(PyExc_ValueError, "%s: the problem is not valid (kinds 0 or 1, 6 joints)", what);
        for (int i = 0; i < 4; i++) Py_DECREF(out[i]);
        return NULL;
    }
    return Py_BuildValue("NNNN", out[0], out[1], out[2], out[3]);
}

/* ik_track(kind, pair, dh, p0, p1, gamma, start[, wide_track, wide_end, wide_steps]) -> (end, status, steps, cond) */
static PyObject *native_ik_track(PyObject *self, PyObject *args)
{
    PyObject *o[9];
    PyArrayObject *a[9] = {NULL};
    PyObject *result = NULL;
    Py_complex gamma;
    apair_ik_options opt;
    apair_ik_default_options(&opt);
    (void)self;
    if (!PyArg_ParseTuple(args, "OOOOODO|ddi", &o[0], &o[1], &o[2], &o[5], &o[6], &gamma, &o[8], &opt.wide_track,
                          &opt.wide_end, &opt.wide_steps)) {
        return NULL;
    }
    npy_intp nk[1] = {-1};
    if (!(a[0] = ik_array(o[0], NPY_INT32, 1, nk, "kind"))) goto done;
    npy_intp n = PyArray_DIM(a[0], 0);
    if (n != 6) {
        PyErr_SetString(PyExc_ValueError, "kind: 6 joints");
        goto done;
    }
    npy_intp s_pair[2] = {n, 2}, s_dh[2] = {n, 4}, s_p[1] = {7}, s_start[2] = {-1, n};
    if (!(a[1] = ik_array(o[1], NPY_DOUBLE, 2, s_pair, "pair")) || !(a[2] = ik_array(o[2], NPY_DOUBLE, 2, s_dh, "dh")) ||
        !(a[5] = ik_array(o[5], NPY_CDOUBLE, 1, s_p, "p0")) || !(a[6] = ik_array(o[6], NPY_CDOUBLE, 1, s_p, "p1")) ||
        !(a[8] = ik_array(o[8], NPY_CDOUBLE, 2, s_start, "start"))) {
        goto done;
    }
    npy_intp count = PyArray_DIM(a[8], 0), s_out[2] = {count, n};
    PyArrayObject *out[4];
    if (track_outputs(s_out, out)) goto done;
    apair_ik_problem pb = {(int)n, (const int *)PyArray_DATA(a[0]), PyArray_DATA(a[1]), PyArray_DATA(a[2])};
    double g[2] = {gamma.real, gamma.imag};
    int rc;
    Py_BEGIN_ALLOW_THREADS
    rc = apair_ik_track(&pb, &opt, PyArray_DATA(a[5]), PyArray_DATA(a[6]), g, (size_t)count, PyArray_DATA(a[8]),
                        PyArray_DATA(out[0]), PyArray_DATA(out[1]), PyArray_DATA(out[2]), PyArray_DATA(out[3]));
    Py_END_ALLOW_THREADS
    result = track_result(rc, out, "ik_track");
done:
    for (int i = 0; i < 9; i++) Py_XDECREF(a[i]);
    return result;
}

/* ik_track_slice(kind, pair, dh, p, w, ell, dell, t0, dt, times_lambda, gamma, start) -> (end, status, steps, cond) */
static PyObject *native_ik_track_slice(PyObject *self, PyObject *args)
{
    PyObject *o[8];
    PyArrayObject *a[8] = {NULL};
    PyObject *result = NULL;
    Py_complex t0, dt, gamma;
    int times_lambda;
    (void)self;
    if (!PyArg_ParseTuple(args, "OOOOOOODDpDO", &o[0], &o[1], &o[2], &o[3], &o[4], &o[5], &o[6], &t0, &dt,
                          &times_lambda, &gamma, &o[7])) {
        return NULL;
    }
    npy_intp s_kind[1] = {6}, s_pair[2] = {6, 2}, s_dh[2] = {6, 4}, s_p[1] = {7}, s_ell[2] = {2, 6}, s_start[2] = {-1, 7};
    if (!(a[0] = ik_array(o[0], NPY_INT32, 1, s_kind, "kind")) || !(a[1] = ik_array(o[1], NPY_DOUBLE, 2, s_pair, "pair")) ||
        !(a[2] = ik_array(o[2], NPY_DOUBLE, 2, s_dh, "dh")) || !(a[3] = ik_array(o[3], NPY_CDOUBLE, 1, s_p, "p")) ||
        !(a[4] = ik_array(o[4], NPY_CDOUBLE, 1, s_p, "w")) || !(a[5] = ik_array(o[5], NPY_CDOUBLE, 2, s_ell, "ell")) ||
        !(a[6] = ik_array(o[6], NPY_CDOUBLE, 2, s_ell, "dell")) || !(a[7] = ik_array(o[7], NPY_CDOUBLE, 2, s_start, "start"))) {
        goto done;
    }
    npy_intp count = PyArray_DIM(a[7], 0), s_out[2] = {count, 7};
    PyArrayObject *out[4];
    if (track_outputs(s_out, out)) goto done;
    apair_ik_problem pb = {6, (const int *)PyArray_DATA(a[0]), PyArray_DATA(a[1]), PyArray_DATA(a[2])};
    apair_ik_slice sl;
    memcpy(sl.p, PyArray_DATA(a[3]), sizeof sl.p);
    memcpy(sl.w, PyArray_DATA(a[4]), sizeof sl.w);
    memcpy(sl.ell, PyArray_DATA(a[5]), sizeof sl.ell);
    memcpy(sl.dell, PyArray_DATA(a[6]), sizeof sl.dell);
    sl.t0[0] = t0.real; sl.t0[1] = t0.imag;
    sl.dt[0] = dt.real; sl.dt[1] = dt.imag;
    sl.times_lambda = times_lambda;
    apair_ik_options opt;
    apair_ik_default_options(&opt);
    double g[2] = {gamma.real, gamma.imag};
    int rc;
    Py_BEGIN_ALLOW_THREADS
    rc = apair_ik_track_slice(&pb, &opt, &sl, g, (size_t)count, PyArray_DATA(a[7]), PyArray_DATA(out[0]),
                              PyArray_DATA(out[1]), PyArray_DATA(out[2]), PyArray_DATA(out[3]));
    Py_END_ALLOW_THREADS
    result = track_result(rc, out, "ik_track_slice");
done:
    for (int i = 0; i < 8; i++) Py_XDECREF(a[i]);
    return result;
}

/* ik6r_angles(x3, vec, P, L, sigma, dh, T) -> theta */
static PyObject *native_ik6r_angles(PyObject *self, PyObject *args)
{
    PyObject *o[7];
    PyArrayObject *a[7] = {NULL};
    PyObject *result = NULL;
    (void)self;
    if (!PyArg_ParseTuple(args, "OOOOOOO", &o[0], &o[1], &o[2], &o[3], &o[4], &o[5], &o[6])) {
        return NULL;
    }
    npy_intp s_x3[1] = {-1}, s_P[2] = {14, 27}, s_L[2] = {14, 8}, s_sigma[1] = {3}, s_dh[2] = {6, 4}, s_T[2] = {4, 4};
    if (!(a[0] = ik_array(o[0], NPY_CDOUBLE, 1, s_x3, "x3"))) goto done;
    npy_intp count = PyArray_DIM(a[0], 0), s_vec[2] = {count, 24}, s_out[2] = {count, 6};
    if (!(a[1] = ik_array(o[1], NPY_CDOUBLE, 2, s_vec, "vec")) || !(a[2] = ik_array(o[2], NPY_DOUBLE, 2, s_P, "P")) ||
        !(a[3] = ik_array(o[3], NPY_DOUBLE, 2, s_L, "L")) || !(a[4] = ik_array(o[4], NPY_DOUBLE, 1, s_sigma, "sigma")) ||
        !(a[5] = ik_array(o[5], NPY_DOUBLE, 2, s_dh, "dh")) || !(a[6] = ik_array(o[6], NPY_DOUBLE, 2, s_T, "T"))) {
        goto done;
    }
    PyArrayObject *theta = (PyArrayObject *)PyArray_SimpleNew(2, s_out, NPY_CDOUBLE);
    if (!theta) goto done;
    apair_ik6r_angles((size_t)count, PyArray_DATA(a[0]), PyArray_DATA(a[1]), PyArray_DATA(a[2]), PyArray_DATA(a[3]),
                      PyArray_DATA(a[4]), PyArray_DATA(a[5]), PyArray_DATA(a[6]), PyArray_DATA(theta));
    result = (PyObject *)theta;
done:
    for (int i = 0; i < 7; i++) Py_XDECREF(a[i]);
    return result;
}

/* ik_newton(kind, pair, dh, p, theta, max_steps, tol, floor, stall, imag_max) -> (theta, size) */
static PyObject *native_ik_newton(PyObject *self, PyObject *args)
{
    PyObject *o[5];
    PyArrayObject *a[5] = {NULL};
    PyObject *result = NULL;
    int max_steps;
    double tol, floor_, stall, imag_max;
    (void)self;
    if (!PyArg_ParseTuple(args, "OOOOOidddd", &o[0], &o[1], &o[2], &o[3], &o[4], &max_steps, &tol, &floor_, &stall,
                          &imag_max)) {
        return NULL;
    }
    npy_intp nk[1] = {6}, s_pair[2] = {6, 2}, s_dh[2] = {6, 4}, s_p[1] = {7}, s_theta[2] = {-1, 6};
    if (!(a[0] = ik_array(o[0], NPY_INT32, 1, nk, "kind")) || !(a[1] = ik_array(o[1], NPY_DOUBLE, 2, s_pair, "pair")) ||
        !(a[2] = ik_array(o[2], NPY_DOUBLE, 2, s_dh, "dh")) || !(a[3] = ik_array(o[3], NPY_CDOUBLE, 1, s_p, "p")) ||
        !(a[4] = ik_array(o[4], NPY_CDOUBLE, 2, s_theta, "theta"))) {
        goto done;
    }
    npy_intp count = PyArray_DIM(a[4], 0), s_size[1] = {count};
    PyArrayObject *theta = (PyArrayObject *)PyArray_NewCopy(a[4], NPY_CORDER);
    PyArrayObject *size = (PyArrayObject *)PyArray_SimpleNew(1, s_size, NPY_DOUBLE);
    if (!theta || !size) {
        Py_XDECREF(theta); Py_XDECREF(size);
        goto done;
    }
    apair_ik_problem pb = {6, (const int *)PyArray_DATA(a[0]), PyArray_DATA(a[1]), PyArray_DATA(a[2])};
    int rc;
    Py_BEGIN_ALLOW_THREADS
    rc = apair_ik_newton(&pb, PyArray_DATA(a[3]), (size_t)count, PyArray_DATA(theta), max_steps, tol, floor_, stall,
                         imag_max, PyArray_DATA(size));
    Py_END_ALLOW_THREADS
    if (rc) {
        PyErr_SetString(PyExc_ValueError, "ik_newton: the problem is not valid (kinds 0 or 1, 6 joints)");
        Py_DECREF(theta); Py_DECREF(size);
        goto done;
    }
    result = Py_BuildValue("NN", theta, size);
done:
    for (int i = 0; i < 5; i++) Py_XDECREF(a[i]);
    return result;
}

/* ik_local(kind, pair, dh, lower, upper, scale, target (count, 4, 4), seed (count, n), tol, max_iter)
 * -> (q, residual, converged) */
static PyObject *native_ik_local(PyObject *self, PyObject *args)
{
    PyObject *o[8];
    PyArrayObject *a[8] = {NULL};
    PyObject *result = NULL;
    double scale, tol;
    int max_iter;
    (void)self;
    if (!PyArg_ParseTuple(args, "OOOOOdOOdi", &o[0], &o[1], &o[2], &o[3], &o[4], &scale, &o[6], &o[7], &tol, &max_iter)) {
        return NULL;
    }
    npy_intp nk[1] = {-1};
    if (!(a[0] = ik_array(o[0], NPY_INT32, 1, nk, "kind"))) goto done;
    npy_intp n = PyArray_DIM(a[0], 0);
    npy_intp s_pair[2] = {n, 2}, s_dh[2] = {n, 4}, s_lim[1] = {n}, s_T[3] = {-1, 4, 4}, s_q[2] = {-1, n};
    if (!(a[1] = ik_array(o[1], NPY_DOUBLE, 2, s_pair, "pair")) || !(a[2] = ik_array(o[2], NPY_DOUBLE, 2, s_dh, "dh")) ||
        !(a[3] = ik_array(o[3], NPY_DOUBLE, 1, s_lim, "lower")) || !(a[4] = ik_array(o[4], NPY_DOUBLE, 1, s_lim, "upper")) ||
        !(a[6] = ik_array(o[6], NPY_DOUBLE, 3, s_T, "target")) || !(a[7] = ik_array(o[7], NPY_DOUBLE, 2, s_q, "seed"))) {
        goto done;
    }
    npy_intp count = PyArray_DIM(a[7], 0), s_out[2] = {count, n};
    if (PyArray_DIM(a[6], 0) != count && PyArray_DIM(a[6], 0) != 1) {
        PyErr_SetString(PyExc_ValueError, "target: one pose, or one per seed");
        goto done;
    }
    PyArrayObject *q = (PyArrayObject *)PyArray_SimpleNew(2, s_out, NPY_DOUBLE);
    PyArrayObject *res = (PyArrayObject *)PyArray_SimpleNew(1, s_out, NPY_DOUBLE);
    PyArrayObject *conv = (PyArrayObject *)PyArray_SimpleNew(1, s_out, NPY_INT32);
    if (!q || !res || !conv) {
        Py_XDECREF(q); Py_XDECREF(res); Py_XDECREF(conv);
        goto done;
    }
    apair_ik_chain ch = {(int)n, (const int *)PyArray_DATA(a[0]), PyArray_DATA(a[1]), PyArray_DATA(a[2]),
                         PyArray_DATA(a[3]), PyArray_DATA(a[4]), scale};
    int rc;
    ptrdiff_t tstride = PyArray_DIM(a[6], 0) == 1 ? 0 : 16;
    Py_BEGIN_ALLOW_THREADS
    rc = apair_ik_local(&ch, (size_t)count, PyArray_DATA(a[6]), tstride, PyArray_DATA(a[7]), n, tol, max_iter,
                        PyArray_DATA(q), PyArray_DATA(res), PyArray_DATA(conv));
    Py_END_ALLOW_THREADS
    if (rc) {
        PyErr_SetString(PyExc_ValueError, "ik_local: the chain is not valid (kinds 0, 1 or 2; 1 to 6 joints)");
        Py_DECREF(q); Py_DECREF(res); Py_DECREF(conv);
        goto done;
    }
    result = Py_BuildValue("NNN", q, res, conv);
done:
    for (int i = 0; i < 8; i++) Py_XDECREF(a[i]);
    return result;
}

/* ik4_pencil(C (d3+1, d4+1, 8), Qf (8, 8), af (2), Qg (8, 8), ag (2), cond_max, deflate, deflate_tol)
 * -> (f, g, M), or None where the leading coefficients are ill-conditioned */
static PyObject *native_ik4_pencil(PyObject *self, PyObject *args)
{
    PyObject *o[5];
    PyArrayObject *a[5] = {NULL};
    PyObject *result = NULL;
    double cond_max, deflate_tol;
    int deflate;
    (void)self;
    if (!PyArg_ParseTuple(args, "OOOOOdid", &o[0], &o[1], &o[2], &o[3], &o[4], &cond_max, &deflate, &deflate_tol)) {
        return NULL;
    }
    npy_intp s_img[3] = {-1, -1, 8}, s_Q[2] = {8, 8}, s_a[1] = {2};
    if (!(a[0] = ik_array(o[0], NPY_DOUBLE, 3, s_img, "C")) || !(a[1] = ik_array(o[1], NPY_DOUBLE, 2, s_Q, "Qf")) ||
        !(a[2] = ik_array(o[2], NPY_INT32, 1, s_a, "af")) || !(a[3] = ik_array(o[3], NPY_DOUBLE, 2, s_Q, "Qg")) ||
        !(a[4] = ik_array(o[4], NPY_INT32, 1, s_a, "ag"))) {
        goto done;
    }
    int d3 = (int)PyArray_DIM(a[0], 0) - 1, d4 = (int)PyArray_DIM(a[0], 1) - 1;
    const int *af = (const int *)PyArray_DATA(a[2]), *ag = (const int *)PyArray_DATA(a[4]);
    npy_intp s_f[2] = {2 * d3 - 2 * af[0] + 1, 2 * d4 - 2 * af[1] + 1};
    npy_intp s_g[2] = {2 * d3 - 2 * ag[0] + 1, 2 * d4 - 2 * ag[1] + 1};
    if (deflate & 1) { /* (g - a f) / (1 + u3^2): degree max(G0, F0 + 1) - 2 in u3 */
        s_g[0] = (s_g[0] > s_f[0] + 1 ? s_g[0] : s_f[0] + 1) - 2;
    }
    if (deflate & 2) { /* and the same in u4 */
        s_g[1] = (s_g[1] > s_f[1] + 1 ? s_g[1] : s_f[1] + 1) - 2;
    }
    if (s_f[0] < 2 || s_f[1] < 1 || s_g[0] < 2 || s_g[1] < 1) {
        PyErr_SetString(PyExc_ValueError, "ik4_pencil: the factors leave an image constant in u3");
        goto done;
    }
    npy_intp n = (s_g[1] - 1) * (s_f[0] - 1) + (s_f[1] - 1) * (s_g[0] - 1), s_M[2] = {n, n};
    PyArrayObject *f = (PyArrayObject *)PyArray_SimpleNew(2, s_f, NPY_DOUBLE);
    PyArrayObject *g = (PyArrayObject *)PyArray_SimpleNew(2, s_g, NPY_DOUBLE);
    PyArrayObject *M = (PyArrayObject *)PyArray_SimpleNew(2, s_M, NPY_DOUBLE);
    if (!f || !g || !M) {
        Py_XDECREF(f); Py_XDECREF(g); Py_XDECREF(M);
        goto done;
    }
    int size = 0;
    int rc = apair_ik4_pencil(d3, d4, PyArray_DATA(a[0]), PyArray_DATA(a[1]), af, PyArray_DATA(a[3]), ag, cond_max,
                              deflate, deflate_tol, PyArray_DATA(f), PyArray_DATA(g), PyArray_DATA(M), &size);
    if (rc < 0) {
        PyErr_SetString(PyExc_ValueError, "ik4_pencil: degrees out of range");
        Py_DECREF(f); Py_DECREF(g); Py_DECREF(M);
        goto done;
    }
    if (rc > 0) {
        Py_DECREF(f); Py_DECREF(g); Py_DECREF(M);
        Py_INCREF(Py_None);
        result = Py_None;
        goto done;
    }
    result = Py_BuildValue("NNN", f, g, M);
done:
    for (int i = 0; i < 5; i++) Py_XDECREF(a[i]);
    return result;
}

/* ik4_screen(u3 (r), C (d3+1, d4+1, 8), f, g, Q (nq, 8, 8), probe (N), tol (3))
 * -> (status (r), u4 (r), W (r, 8), rel (r), two (r, 2, 2), two_ok (r, 2), W2 (r, 2, 8), rel2 (r, 2)) */
static PyObject *native_ik4_screen(PyObject *self, PyObject *args)
{
    PyObject *o[7];
    PyArrayObject *a[7] = {NULL}, *out[8] = {NULL};
    PyObject *result = NULL;
    (void)self;
    if (!PyArg_ParseTuple(args, "OOOOOOO", &o[0], &o[1], &o[2], &o[3], &o[4], &o[5], &o[6])) {
        return NULL;
    }
    npy_intp s_u[1] = {-1}, s_C[3] = {-1, -1, 8}, s_p[2] = {-1, -1}, s_Q[3] = {-1, 8, 8}, s_tol[1] = {3};
    if (!(a[0] = ik_array(o[0], NPY_DOUBLE, 1, s_u, "u3")) || !(a[1] = ik_array(o[1], NPY_DOUBLE, 3, s_C, "C")) ||
        !(a[2] = ik_array(o[2], NPY_DOUBLE, 2, s_p, "f")) || !(a[3] = ik_array(o[3], NPY_DOUBLE, 2, s_p, "g")) ||
        !(a[4] = ik_array(o[4], NPY_DOUBLE, 3, s_Q, "Q")) || !(a[6] = ik_array(o[6], NPY_DOUBLE, 1, s_tol, "tol"))) {
        goto done;
    }
    int F1 = (int)PyArray_DIM(a[2], 1) - 1, G1 = (int)PyArray_DIM(a[3], 1) - 1;
    npy_intp s_probe[1] = {F1 + G1};
    if (!(a[5] = ik_array(o[5], NPY_DOUBLE, 1, s_probe, "probe"))) goto done;
    npy_intp r = PyArray_DIM(a[0], 0);
    npy_intp shapes[8][3] = {{r}, {r}, {r, 8}, {r}, {r, 2, 2}, {r, 2}, {r, 2, 8}, {r, 2}};
    int nds[8] = {1, 1, 2, 1, 3, 2, 3, 2};
    int types[8] = {NPY_INT32, NPY_DOUBLE, NPY_DOUBLE, NPY_DOUBLE, NPY_DOUBLE, NPY_INT32, NPY_DOUBLE, NPY_DOUBLE};
    for (int k = 0; k < 8; k++) {
        if (!(out[k] = (PyArrayObject *)PyArray_SimpleNew(nds[k], shapes[k], types[k]))) goto done;
    }
    int rc = apair_ik4_screen((size_t)r, PyArray_DATA(a[0]), (int)PyArray_DIM(a[1], 0) - 1,
                              (int)PyArray_DIM(a[1], 1) - 1, PyArray_DATA(a[1]), PyArray_DATA(a[2]),
                              (int)PyArray_DIM(a[2], 0) - 1, F1, PyArray_DATA(a[3]), (int)PyArray_DIM(a[3], 0) - 1, G1,
                              (int)PyArray_DIM(a[4], 0), PyArray_DATA(a[4]), PyArray_DATA(a[5]), PyArray_DATA(a[6]),
                              PyArray_DATA(out[0]), PyArray_DATA(out[1]), PyArray_DATA(out[2]), PyArray_DATA(out[3]),
                              PyArray_DATA(out[4]), PyArray_DATA(out[5]), PyArray_DATA(out[6]), PyArray_DATA(out[7]));
    if (rc) {
        PyErr_SetString(PyExc_ValueError, "ik4_screen: the Sylvester size is out of range");
        goto done;
    }
    result = Py_BuildValue("NNNNNNNN", out[0], out[1], out[2], out[3], out[4], out[5], out[6], out[7]);
    for (int k = 0; k < 8; k++) out[k] = NULL; /* owned by the result now */
done:
    for (int k = 0; k < 8; k++) Py_XDECREF(out[k]);
    for (int i = 0; i < 7; i++) Py_XDECREF(a[i]);
    return result;
}

/* ik4_left(W (r, 8), Zmap (d1+1, 8, 8), P2 (d2+1, 8), joint (4), tol (4)) -> (status (r), u1 (r), u2 (r, 2), ok (r, 2)) */
static PyObject *native_ik4_left(PyObject *self, PyObject *args)
{
    PyObject *o[5];
    PyArrayObject *a[5] = {NULL};
    PyObject *result = NULL;
    (void)self;
    if (!PyArg_ParseTuple(args, "OOOOO", &o[0], &o[1], &o[2], &o[3], &o[4])) {
        return NULL;
    }
    npy_intp s_W[2] = {-1, 8}, s_Z[3] = {-1, 8, 8}, s_P[2] = {-1, 8}, s_j[1] = {4}, s_tol[1] = {4};
    if (!(a[0] = ik_array(o[0], NPY_DOUBLE, 2, s_W, "W")) || !(a[1] = ik_array(o[1], NPY_DOUBLE, 3, s_Z, "Zmap")) ||
        !(a[2] = ik_array(o[2], NPY_DOUBLE, 2, s_P, "P2")) || !(a[3] = ik_array(o[3], NPY_DOUBLE, 1, s_j, "joint")) ||
        !(a[4] = ik_array(o[4], NPY_DOUBLE, 1, s_tol, "tol"))) {
        goto done;
    }
    npy_intp count = PyArray_DIM(a[0], 0), s_two[2] = {count, 2};
    PyArrayObject *status = (PyArrayObject *)PyArray_SimpleNew(1, s_two, NPY_INT32);
    PyArrayObject *u1 = (PyArrayObject *)PyArray_SimpleNew(1, s_two, NPY_DOUBLE);
    PyArrayObject *u2 = (PyArrayObject *)PyArray_SimpleNew(2, s_two, NPY_DOUBLE);
    PyArrayObject *ok = (PyArrayObject *)PyArray_SimpleNew(2, s_two, NPY_INT32);
    if (!status || !u1 || !u2 || !ok) {
        Py_XDECREF(status); Py_XDECREF(u1); Py_XDECREF(u2); Py_XDECREF(ok);
        goto done;
    }
    int rc = apair_ik4_left((size_t)count, PyArray_DATA(a[0]), (int)PyArray_DIM(a[1], 0) - 1, PyArray_DATA(a[1]),
                            (int)PyArray_DIM(a[2], 0) - 1, PyArray_DATA(a[2]), PyArray_DATA(a[3]), PyArray_DATA(a[4]),
                            PyArray_DATA(status), PyArray_DATA(u1), PyArray_DATA(u2), PyArray_DATA(ok));
    if (rc) {
        PyErr_SetString(PyExc_ValueError, "ik4_left: degrees out of range");
        Py_DECREF(status); Py_DECREF(u1); Py_DECREF(u2); Py_DECREF(ok);
        goto done;
    }
    result = Py_BuildValue("NNNN", status, u1, u2, ok);
done:
    for (int i = 0; i < 5; i++) Py_XDECREF(a[i]);
    return result;
}

static PyMethodDef native_methods[] = {
    {"call", (PyCFunction)(void (*)(void))native_call, METH_FASTCALL,
     "call(index, *inputs) -> list of outputs, or None if an input needs converting first."},
    {"names", native_names, METH_NOARGS, "names() -> the kernel names, in registry (index) order."},
    {"enable", native_enable, METH_O, "enable(flag): whether Chain.call may evaluate (the C backend is in use)."},
    {"kernel_address", native_kernel_address, METH_O, "kernel_address(index) -> address of the registry entry."},
    {"ik_track_slice", native_ik_track_slice, METH_VARARGS,
     "ik_track_slice(kind, pair, dh, p, w, ell, dell, t0, dt, times_lambda, gamma, start) -> (end, status, steps, cond): "
     "apair_ik_track_slice."},
    {"ik_track", native_ik_track, METH_VARARGS,
     "ik_track(kind, pair, dh, p0, p1, gamma, start) -> (end, status, steps, cond): apair_ik_track."},
    {"ik6r_angles", native_ik6r_angles, METH_VARARGS,
     "ik6r_angles(x3, vec, P, L, sigma, dh, T) -> theta: apair_ik6r_angles."},
    {"ik_newton", native_ik_newton, METH_VARARGS,
     "ik_newton(kind, pair, dh, p, theta, max_steps, tol, floor, stall, imag_max) -> (theta, size): apair_ik_newton."},
    {"ik4_pencil", native_ik4_pencil, METH_VARARGS,
     "ik4_pencil(C, Qf, af, Qg, ag, cond_max, deflate, deflate_tol) -> (f, g, M) or None: apair_ik4_pencil."},
    {"ik4_screen", native_ik4_screen, METH_VARARGS,
     "ik4_screen(u3, C, f, g, Q, probe, tol) -> (status, u4, W, rel, two, two_ok, W2, rel2): apair_ik4_screen."},
    {"ik4_left", native_ik4_left, METH_VARARGS,
     "ik4_left(W, Zmap, P2, joint, tol) -> (status, u1, u2, ok): apair_ik4_left."},
    {"ik_local", native_ik_local, METH_VARARGS,
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
