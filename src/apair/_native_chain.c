/*
 * apair._native.Chain: the fast path of AChain's methods, and enable(flag), which says whether it
 * may evaluate (apair.kernels sets it once the C backend is chosen). Part of the binding
 * apair._native (see _native.c; _native.h is what its files share).
 *
 * One object per chain holds, per method, the kernels that compute it (a generic chain kernel fed
 * by the joints' law kernels, or a specialised kernel of that chain taking q itself; a method of
 * several outputs may be two kernels on the same inputs, as the inverse dynamics' derivatives and
 * the mass matrix, returned as one tuple), the design arrays, and the joints' ranges. The law
 * values, and d''' of each law (law_<kind>_d3) for the kernels that take it, are formed once per
 * item, and only for a method whose kernels take them. call(method, q, ...) evaluates it in one
 * native call when every input is already canonical (float64 arrays, native byte order,
 * C-contiguous, aligned, the same shape (..., n), finite, inside the joints' ranges) and every
 * output is finite. Otherwise it returns None and AChain takes its validating path, which raises
 * the ValueError that names the argument, or converts and broadcasts (so this file needs no error
 * messages of its own and cannot disagree with them).
 */
#include "_native.h"

#define MAX_JOINTS 7
#define MAX_METHODS 16
#define MAX_STEPS 2   /* kernels of one method */
#define MAX_OUTPUTS 3 /* outputs of one method, over its kernels */
#define MAX_DESIGN 8
#define CHAIN_BLOCK 512 /* items whose law values are formed before the chain kernels run on them */

enum { SRC_LAW = -1, SRC_Q = -2, SRC_ARG1 = -3, SRC_ARG2 = -4, SRC_DDDD = -5 };

static int native_enabled = 0; /* set by apair.kernels once the C backend is chosen */

typedef struct {
    const apair_kernel *kernel;
    int source[MAX_ARGS]; /* per kernel input: SRC_* or the index of a design array */
    double *inv;          /* the kernel's design invariants (its split form), or NULL */
} chain_step;

typedef struct {
    int n_steps;   /* its kernels; 0: the method has none here */
    int n_outputs; /* over its kernels */
    int strict;    /* needs every ranged joint strictly inside its range (d' finite) */
    int law;       /* some kernel takes the law values */
    int dddd;      /* some kernel takes d''' of the laws */
    chain_step steps[MAX_STEPS];
} chain_method;

typedef struct {
    PyObject_HEAD
    int n;
    int n_methods;
    int uses_law;
    chain_method methods[MAX_METHODS];
    const apair_kernel *law[MAX_JOINTS];
    const apair_kernel *law_d3[MAX_JOINTS]; /* NULL where not given */
    double law_params[MAX_JOINTS][2];
    double limit[MAX_JOINTS]; /* |theta| (mod 2 pi) range of each joint, INFINITY if unbounded */
    PyObject *design[MAX_DESIGN];
    int n_design;
    PyObject *keep; /* what must outlive the kernels (the loaded library of a specialised chain) */
} ChainObject;

static void chain_dealloc(ChainObject *self)
{
    int i, j;
    for (i = 0; i < self->n_methods; ++i) {
        for (j = 0; j < self->methods[i].n_steps; ++j) {
            PyMem_Free(self->methods[i].steps[j].inv);
        }
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

/* The law kernels: laws = [(address, (params...)[, d3 address or None])] per joint. */
static int init_laws(ChainObject *self, PyObject *laws)
{
    Py_ssize_t i, j;
    for (i = 0; i < PyList_GET_SIZE(laws); ++i) {
        PyObject *item = PyList_GET_ITEM(laws, i), *params;
        if (!PyTuple_Check(item) || PyTuple_GET_SIZE(item) < 2 || PyTuple_GET_SIZE(item) > 3 ||
            !PyTuple_Check(PyTuple_GET_ITEM(item, 1))) {
            PyErr_SetString(PyExc_ValueError, "Chain: a law is (address, params[, d3 address])");
            return -1;
        }
        self->law[i] = kernel_at(PyTuple_GET_ITEM(item, 0));
        if (self->law[i] == NULL) {
            return -1;
        }
        self->law_d3[i] = NULL;
        if (PyTuple_GET_SIZE(item) == 3 && PyTuple_GET_ITEM(item, 2) != Py_None) {
            self->law_d3[i] = kernel_at(PyTuple_GET_ITEM(item, 2));
            if (self->law_d3[i] == NULL) {
                return -1;
            }
            if (self->law_d3[i]->n_inputs != self->law[i]->n_inputs || self->law_d3[i]->n_outputs != 1 ||
                self->law_d3[i]->outputs[0].size != 1) {
                PyErr_SetString(PyExc_ValueError, "Chain: a d3 kernel does not fit its law");
                return -1;
            }
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
    return 0;
}

/* One kernel of a method: where each of its inputs comes from, and its design invariants. */
static int init_step(ChainObject *self, chain_method *m, chain_step *st, PyObject *address, PyObject *design)
{
    int j, d;
    st->kernel = kernel_at(address);
    if (st->kernel == NULL) {
        return -1;
    }
    if (st->kernel->n_inputs > MAX_ARGS || m->n_outputs + st->kernel->n_outputs > MAX_OUTPUTS) {
        PyErr_Format(PyExc_ValueError, "Chain: kernel %s does not fit", st->kernel->name);
        return -1;
    }
    m->n_outputs += st->kernel->n_outputs;
    for (j = 0; j < st->kernel->n_inputs; ++j) {
        const apair_arg *a = &st->kernel->inputs[j];
        const char *name = a->name;
        PyObject *arr;
        if (strcmp(name, "law") == 0 || strcmp(name, "dddd") == 0) {
            const int third = name[0] == 'd';
            for (d = 0; d < self->n; ++d) {
                if (!self->uses_law || (third && self->law_d3[d] == NULL)) {
                    PyErr_Format(PyExc_ValueError, "Chain: %s takes %s but no such law kernels were given",
                                 st->kernel->name, name);
                    return -1;
                }
            }
            st->source[j] = third ? SRC_DDDD : SRC_LAW;
            m->law = 1;
            m->dddd |= third;
            continue;
        }
        if (strcmp(name, "q") == 0 || strcmp(name, "qd") == 0 || strcmp(name, "qdd") == 0 || strcmp(name, "tau") == 0) {
            if (a->rank != 1 || a->shape[0] != self->n) {
                PyErr_Format(PyExc_ValueError, "Chain: %s input %s is not (n,)", st->kernel->name, name);
                return -1;
            }
            st->source[j] = name[0] == 'q' && name[1] == '\0' ? SRC_Q : (strcmp(name, "qd") == 0 ? SRC_ARG1 : SRC_ARG2);
            continue;
        }
        arr = PyDict_GetItemString(design, name);
        if (arr == NULL || !PyArray_Check(arr) || PyArray_TYPE((PyArrayObject *)arr) != NPY_DOUBLE ||
            !PyArray_IS_C_CONTIGUOUS((PyArrayObject *)arr) || !PyArray_ISALIGNED((PyArrayObject *)arr) ||
            !PyArray_ISNOTSWAPPED((PyArrayObject *)arr) || PyArray_SIZE((PyArrayObject *)arr) != a->size) {
            PyErr_Format(PyExc_ValueError, "Chain: design input %s of %s is missing or malformed", name, st->kernel->name);
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
        st->source[j] = d;
    }
    if (st->kernel->n_invariants > 0 && st->kernel->invariants != NULL && st->kernel->core != NULL) {
        /* the design never changes: its invariants once, here, and single items go to the core */
        const double *in[MAX_ARGS];
        st->inv = (double *)PyMem_Malloc(sizeof(double) * (size_t)st->kernel->n_invariants);
        if (st->inv == NULL) {
            PyErr_NoMemory();
            return -1;
        }
        for (j = 0; j < st->kernel->n_inputs; ++j) {
            in[j] = st->source[j] >= 0 ? (const double *)PyArray_DATA((PyArrayObject *)self->design[st->source[j]]) : NULL;
        }
        st->kernel->invariants(in, st->inv);
    }
    return 0;
}

/* Chain(n, methods, laws, limits, design, keep): methods = [(kernel address, a tuple of them or
 * None, strict)], laws = [(law kernel address, (params...)[, law_<kind>_d3 address or None])] per
 * joint (empty when no method takes law values), limits = per joint range (inf if none), design =
 * {name: float64 array}, keep = any object. A method with None among its kernels has none. */
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
    if (init_laws(self, laws) < 0) {
        return -1;
    }
    self->n_methods = (int)PyList_GET_SIZE(methods);
    for (i = 0; i < self->n_methods; ++i) {
        PyObject *item = PyList_GET_ITEM(methods, i), *kernels;
        chain_method *m = &self->methods[i];
        if (!PyTuple_Check(item) || PyTuple_GET_SIZE(item) != 2) {
            PyErr_SetString(PyExc_ValueError, "Chain: a method is (address, addresses or None, strict)");
            return -1;
        }
        m->strict = PyObject_IsTrue(PyTuple_GET_ITEM(item, 1));
        kernels = PyTuple_GET_ITEM(item, 0);
        if (!PyTuple_Check(kernels)) { /* one kernel (or None) */
            kernels = PyTuple_Pack(1, kernels);
        } else {
            Py_INCREF(kernels);
        }
        if (kernels == NULL) {
            return -1;
        }
        if (PyTuple_GET_SIZE(kernels) > MAX_STEPS) {
            Py_DECREF(kernels);
            PyErr_SetString(PyExc_ValueError, "Chain: too many kernels for one method");
            return -1;
        }
        for (j = 0; j < PyTuple_GET_SIZE(kernels); ++j) {
            if (PyTuple_GET_ITEM(kernels, j) == Py_None) {
                break;
            }
        }
        if (j == PyTuple_GET_SIZE(kernels)) {
            for (j = 0; j < PyTuple_GET_SIZE(kernels); ++j) {
                m->n_steps = (int)j + 1; /* so that dealloc frees what init_step allocated */
                if (init_step(self, m, &m->steps[j], PyTuple_GET_ITEM(kernels, j), design) < 0) {
                    Py_DECREF(kernels);
                    return -1;
                }
            }
        }
        Py_DECREF(kernels);
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

/* The law values of `count` items of q into law[count][n][5], and with `dddd` d''' into
 * dddd[count][n]. */
static void fill_law(const ChainObject *self, const double *q, size_t count, double *law, double *dddd)
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
            if (dddd != NULL) {
                out[0] = dddd + k * (size_t)self->n + (size_t)i;
                self->law_d3[i]->eval(in, out);
            }
        }
    }
}

/* Runs the method's kernels on items done .. done + items - 1 (law values of those in law, dddd). */
static void run_steps(const ChainObject *self, const chain_method *m, const double *const *given, size_t done,
                      size_t items, size_t count, const double *law, const double *dddd, double *const *outp)
{
    const double *in[MAX_ARGS];
    ptrdiff_t stride[MAX_ARGS];
    double *o[MAX_OUTPUTS];
    int s, i, first = 0;
    for (s = 0; s < m->n_steps; ++s) {
        const chain_step *st = &m->steps[s];
        const apair_kernel *k = st->kernel;
        for (i = 0; i < k->n_inputs; ++i) {
            const int src = st->source[i];
            stride[i] = (ptrdiff_t)k->inputs[i].size;
            if (src == SRC_LAW) {
                in[i] = law;
            } else if (src == SRC_DDDD) {
                in[i] = dddd;
            } else if (src <= SRC_Q) {
                in[i] = given[SRC_Q - src] + done * (size_t)self->n;
            } else {
                in[i] = (const double *)PyArray_DATA((PyArrayObject *)self->design[src]);
                stride[i] = 0;
            }
        }
        for (i = 0; i < k->n_outputs; ++i) {
            o[i] = outp[first + i] + done * (size_t)k->outputs[i].size;
        }
        if (count == 1 && st->inv != NULL) {
            k->core(st->inv, in, o);
        } else if (count == 1) {
            k->eval(in, o);
        } else {
            k->eval_batch(items, in, stride, o);
        }
        first += k->n_outputs;
    }
}

/* The output arrays of a method: (batch dims of q) + each output's shape. */
static int new_outputs(const chain_method *m, PyArrayObject *q, PyArrayObject **out, double **outp)
{
    npy_intp dims[MAX_DIMS];
    int s, i, j, c = 0;
    const int nd = PyArray_NDIM(q) - 1;
    for (i = 0; i < nd; ++i) {
        dims[i] = PyArray_DIM(q, i);
    }
    for (s = 0; s < m->n_steps; ++s) {
        const apair_kernel *k = m->steps[s].kernel;
        for (i = 0; i < k->n_outputs; ++i, ++c) {
            if (nd + k->outputs[i].rank > MAX_DIMS) {
                return 0;
            }
            for (j = 0; j < k->outputs[i].rank; ++j) {
                dims[nd + j] = k->outputs[i].shape[j];
            }
            out[c] = (PyArrayObject *)PyArray_SimpleNew(nd + k->outputs[i].rank, dims, NPY_DOUBLE);
            if (out[c] == NULL) {
                return -1;
            }
            outp[c] = (double *)PyArray_DATA(out[c]);
        }
    }
    return 1;
}

static PyObject *chain_call(ChainObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    const chain_method *m;
    PyArrayObject *q, *out[MAX_OUTPUTS] = {NULL, NULL, NULL};
    PyObject *result = NULL;
    const double *given[3];
    double *outp[MAX_OUTPUTS];
    double law_one[MAX_JOINTS * 6];
    double *law = law_one, *dddd = NULL;
    size_t count, size, done, block;
    PyThreadState *released = NULL;
    long method;
    int i, s, made, ok = 1;

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
    if (!native_enabled || m->n_steps == 0 || !canonical(args[1], NULL, self->n)) {
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
    for (s = 0; s < m->n_steps; ++s) {
        const apair_kernel *k = m->steps[s].kernel;
        for (i = 0; i < k->n_inputs; ++i) {
            const int src = m->steps[s].source[i];
            if ((src == SRC_ARG1 && nargs < 3) || (src == SRC_ARG2 && nargs < 4)) {
                PyErr_Format(PyExc_TypeError, "Chain.call: %s needs more inputs", k->name);
                return NULL;
            }
        }
    }
    made = new_outputs(m, q, out, outp);
    if (made <= 0) {
        for (i = 0; i < m->n_outputs; ++i) {
            Py_XDECREF(out[i]);
        }
        if (made < 0) {
            return NULL;
        }
        Py_RETURN_NONE;
    }
    block = count < CHAIN_BLOCK ? count : CHAIN_BLOCK;
    if (count > 1 && m->law) {
        law = (double *)PyMem_RawMalloc(sizeof(double) * 6 * (size_t)self->n * block);
        if (law == NULL) {
            for (i = 0; i < m->n_outputs; ++i) {
                Py_DECREF(out[i]);
            }
            return PyErr_NoMemory();
        }
    }
    if (m->dddd) {
        dddd = law + 5 * (size_t)self->n * block; /* after the law values of a block */
    }
    if (count >= NOGIL_COUNT) {
        released = PyEval_SaveThread();
    }
    for (done = 0; done < count;) {
        const size_t items = count - done < CHAIN_BLOCK ? count - done : CHAIN_BLOCK;
        if (m->law) {
            fill_law(self, given[0] + done * (size_t)self->n, items, law, dddd);
        }
        run_steps(self, m, given, done, items, count, law, dddd, outp);
        done += items;
    }
    for (s = 0, i = 0; s < m->n_steps; ++s) {
        const apair_kernel *k = m->steps[s].kernel;
        int j;
        for (j = 0; j < k->n_outputs; ++j, ++i) {
            ok = ok && all_finite(outp[i], count * (size_t)k->outputs[j].size);
        }
    }
    if (released != NULL) {
        PyEval_RestoreThread(released);
    }
    if (law != law_one) {
        PyMem_RawFree(law);
    }
    if (!ok) {
        for (i = 0; i < m->n_outputs; ++i) {
            Py_DECREF(out[i]);
        }
        Py_RETURN_NONE;
    }
    if (m->n_outputs == 1) {
        return (PyObject *)out[0];
    }
    result = PyTuple_New(m->n_outputs);
    if (result == NULL) {
        for (i = 0; i < m->n_outputs; ++i) {
            Py_DECREF(out[i]);
        }
        return NULL;
    }
    for (i = 0; i < m->n_outputs; ++i) {
        PyTuple_SET_ITEM(result, i, (PyObject *)out[i]); /* steals the reference */
    }
    return result;
}

static PyMethodDef chain_methods[] = {
    {"call", (PyCFunction)(void (*)(void))chain_call, METH_FASTCALL,
     "call(method, q[, a[, b]]) -> the method's output (a tuple for several), or None when the inputs need the "
     "validating path."},
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

/* enable(flag): whether Chain.call (and ClosedIK.call) may evaluate (the C backend is in use). */
PyObject *apair_native_enable(PyObject *self, PyObject *flag)
{
    (void)self;
    native_enabled = PyObject_IsTrue(flag) == 1;
    Py_RETURN_NONE;
}

int apair_native_enabled(void) { return native_enabled; }
