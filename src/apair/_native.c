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
 * The rest of the module is in _native_chain.c (Chain: one chain's methods in one native call) and
 * _native_ik.c (the inverse-kinematics solvers of the hand-written C, ik_*, marshalled by one
 * table-driven function, and LocalIK, ik_local's single-pose fast path) and _native_closed.c
 * (ClosedIK, the single-pose fast path of ik for the chains solved in closed form); _native.h is
 * what they share.
 */
#define APAIR_NATIVE_MODULE /* this file calls import_array() */
#include "_native.h"

#ifndef APAIR_SOURCES_HASH /* set by setup.py: the SHA-256 of the generated C files compiled */
#error "APAIR_SOURCES_HASH must be defined (build with setup.py)"
#endif

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

static PyMethodDef native_methods[] = {
    {"call", (PyCFunction)(void (*)(void))native_call, METH_FASTCALL,
     "call(index, *inputs) -> list of outputs, or None if an input needs converting first."},
    {"names", native_names, METH_NOARGS, "names() -> the kernel names, in registry (index) order."},
    {"enable", apair_native_enable, METH_O, "enable(flag): whether Chain.call may evaluate (the C backend is in use)."},
    {"kernel_address", native_kernel_address, METH_O, "kernel_address(index) -> address of the registry entry."},
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
    if (PyType_Ready(&apair_native_chain_type) < 0 || PyType_Ready(&apair_native_local_ik_type) < 0 ||
        PyType_Ready(&apair_native_closed_ik_type) < 0) {
        return NULL;
    }
    m = PyModule_Create(&native_module);
    if (m == NULL) {
        return NULL;
    }
    if (PyModule_AddFunctions(m, apair_native_ik_methods) < 0) {
        Py_DECREF(m);
        return NULL;
    }
    if (PyModule_AddType(m, &apair_native_local_ik_type) < 0 || PyModule_AddType(m, &apair_native_closed_ik_type) < 0) {
        Py_DECREF(m);
        return NULL;
    }
    Py_INCREF(&apair_native_chain_type);
    if (PyModule_AddObject(m, "Chain", (PyObject *)&apair_native_chain_type) < 0 ||
        PyModule_AddIntConstant(m, "KERNEL_SIZE", (long)sizeof(apair_kernel)) < 0) {
        Py_DECREF(&apair_native_chain_type);
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
