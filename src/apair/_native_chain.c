/*
 * apair._native.Chain: the fast path of AChain's methods, and enable(flag), which says whether it
 * may evaluate (apair.kernels sets it once the C backend is chosen). Part of the binding
 * apair._native (see _native.c; _native.h is what its files share).
 *
 * One object per chain holds, per method, the kernel that computes it (a generic chain kernel fed
 * by the joints' law kernels, or a specialised kernel of that chain taking q itself), the design
 * arrays, and the joints' ranges. call(method, q, ...) evaluates it in one native call when every
 * input is already canonical (float64 arrays, native byte order, C-contiguous, aligned, the same
 * shape (..., n), finite, inside the joints' ranges) and every output is finite. Otherwise it
 * returns None and AChain takes its validating path, which raises the ValueError that names the
 * argument, or converts and broadcasts (so this file needs no error messages of its own and cannot
 * disagree with them).
 */
#include "_native.h"

#define MAX_JOINTS 7
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
    if (!PyArray_CheckExact(o)) { /* subclasses (masked arrays: their mask) take the validating path */
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

PyTypeObject apair_native_chain_type = {
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

/* enable(flag): whether Chain.call may evaluate (the C backend is in use). */
PyObject *apair_native_enable(PyObject *self, PyObject *flag)
{
    (void)self;
    native_enabled = PyObject_IsTrue(flag) == 1;
    Py_RETURN_NONE;
}

