/*
 * apair._native's inverse kinematics: the functions ik_*, the entry points of the hand-written
 * solvers in generated/c (apair_ik_track.c, apair_ik6r.c, apair_ik_local.c, apair_ik4.c,
 * apair_ik_wrist.c, apair_ik_parallel.c, apair_ik_three_parallel.c), one row
 * each of the table ik_entries, all marshalled by ik_marshal. Part of the binding apair._native
 * (see _native.c; _native.h is what its files share).
 *
 * A row gives the positional arguments in PyArg_ParseTuple's letters ('O'
 * an array; 'd', 'i', 'D', 'p' a float, int, complex, bool; optional ones after '|'), each array's
 * name, NumPy type and shape (it is converted to a C-contiguous array of that type, then checked),
 * the outputs likewise, and an adapter that calls the C function on the converted pointers. Sizes
 * are numbers, ANY, N (the first argument's length) or ROWS (the length of argument `rows`: the C
 * function's count); `prepare` checks what the shapes cannot say and sets the outputs' shapes they
 * do not give. The adapter runs without the GIL where `nogil`; it returns 0 (the call returns the
 * one output, or the tuple of them), > 0 (None) or < 0 (ValueError(error)).
 *
 * LocalIK is the single-pose fast path of AChain.ik_local: one chain's design and limits held in
 * C, and call(T, q0, tol, max_iter), which runs apair_ik_local on one canonical pose and seed
 * (the numbers of ik_local's batch) or returns None for whatever the validating path must see.
 */
#include "_native.h"

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

/* LAPACK for apair_ik6r_solve: SciPy's scipy.linalg.cython_lapack, its function pointers read once from
 * the module's capsules (its C-API for this use) */
static apair_lapack ik6r_lapack;

static void *lapack_pointer(PyObject *capi, const char *name)
{
    PyObject *capsule = PyDict_GetItemString(capi, name); /* borrowed */
    if (capsule == NULL || !PyCapsule_CheckExact(capsule)) {
        PyErr_Format(PyExc_ImportError, "scipy.linalg.cython_lapack has no %s", name);
        return NULL;
    }
    return PyCapsule_GetPointer(capsule, PyCapsule_GetName(capsule));
}

const apair_lapack *apair_native_lapack(void)
{
    if (ik6r_lapack.dgeev != NULL) return &ik6r_lapack;
    PyObject *module = PyImport_ImportModule("scipy.linalg.cython_lapack"), *capi = NULL;
    const apair_lapack *out = NULL;
    if (module != NULL && (capi = PyObject_GetAttrString(module, "__pyx_capi__")) != NULL && PyDict_Check(capi)) {
        void *gesdd = lapack_pointer(capi, "dgesdd"), *gesv = gesdd ? lapack_pointer(capi, "dgesv") : NULL,
             *geev = gesv ? lapack_pointer(capi, "dgeev") : NULL;
        if (geev != NULL) {
            memcpy(&ik6r_lapack.dgesdd, &gesdd, sizeof gesdd); /* (object to function pointer) */
            memcpy(&ik6r_lapack.dgesv, &gesv, sizeof gesv);
            memcpy(&ik6r_lapack.dgeev, &geev, sizeof geev);
            out = &ik6r_lapack;
        }
    } else if (!PyErr_Occurred()) {
        PyErr_SetString(PyExc_ImportError, "scipy.linalg.cython_lapack has no __pyx_capi__");
    }
    Py_XDECREF(capi);
    Py_XDECREF(module);
    return out;
}

static int prepare_ik6r_solve(ik_call *c)
{
    (void)c;
    return apair_native_lapack() ? 0 : -1;
}

static int run_ik6r_solve(const ik_call *c)
{
    apair_ik_problem pb = {6, in(c, 0), in(c, 1), in(c, 2)};
    return apair_ik6r_solve(&ik6r_lapack, &pb, in(c, 3), in(c, 4), out(c, 0));
}

static int run_ik6r(const ik_call *c)
{
    return apair_ik6r(&ik6r_lapack, in(c, 0), c->s[1].d, in(c, 2), c->s[3].d, out(c, 0), out(c, 1), out(c, 2), out(c, 3));
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
static int run_wrist(const ik_call *c)
{
    return apair_ik_wrist(in(c, 0), c->s[1].d, c->rows, in(c, 2), 16, c->s[3].d, out(c, 0), out(c, 1), out(c, 2),
                          out(c, 3), out(c, 4));
}

static int run_parallel(const ik_call *c)
{
    return apair_ik_parallel(in(c, 0), c->s[1].d, c->rows, in(c, 2), 16, c->s[3].d, out(c, 0), out(c, 1), out(c, 2),
                             out(c, 3), out(c, 4));
}

static int run_three_parallel(const ik_call *c)
{
    return apair_ik_three_parallel(in(c, 0), c->s[1].d, c->rows, in(c, 2), 16, c->s[3].d, out(c, 0), out(c, 1),
                                   out(c, 2), out(c, 3), out(c, 4));
}

static int run_parallel_apair(const ik_call *c)
{
    return apair_ik_parallel_apair(in(c, 0), in(c, 1), c->s[2].d, c->rows, in(c, 3), 16, c->s[4].d, out(c, 0),
                                   out(c, 1), out(c, 2), out(c, 3), out(c, 4));
}

static int run_wrist_apair(const ik_call *c)
{
    return apair_ik_wrist_apair(in(c, 0), in(c, 1), c->s[2].d, c->rows, in(c, 3), 16, c->s[4].d, out(c, 0), out(c, 1),
                                out(c, 2), out(c, 3), out(c, 4));
}

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

enum { IK_TRACK, IK_TRACK_SLICE, IK6R_ANGLES, IK6R_SOLVE, IK6R, IK_NEWTON, IK_LOCAL, IK4_PENCIL, IK4_SCREEN, IK4_LEFT, IK_WRIST, IK_PARALLEL, IK_THREE_PARALLEL,
       IK_PARALLEL_APAIR, IK_WRIST_APAIR };

static const ik_entry ik_entries[] = {
    [IK_TRACK] = {
        .format = "OOOOODO|ddi", /* kind, pair, dh, p0, p1, gamma, start[, wide_track, wide_end, wide_steps] */
        .arrays = {{"kind", I32, 1, {6}}, {"pair", F64, 2, {6, 2}}, {"dh", F64, 2, {6, 4}}, {"p0", C128, 1, {7}},
                   {"p1", C128, 1, {7}}, {"start", C128, 2, {ANY, 6}}},
        .out = {{"end", C128, 2, {ROWS, 6}}, {"status", I32, 1, {ROWS}}, {"steps", I32, 1, {ROWS}},
                {"cond", F64, 1, {ROWS}}},
        .rows = 6, .nogil = 1, .run = run_track,
        .error = "ik_track: the problem is not valid (kinds 0, 1 or 4, 6 joints)",
    },
    [IK_TRACK_SLICE] = {
        .format = "OOOOOOODDpDO", /* kind, pair, dh, p, w, ell, dell, t0, dt, times_lambda, gamma, start */
        .arrays = {{"kind", I32, 1, {6}}, {"pair", F64, 2, {6, 2}}, {"dh", F64, 2, {6, 4}}, {"p", C128, 1, {7}},
                   {"w", C128, 1, {7}}, {"ell", C128, 2, {2, 6}}, {"dell", C128, 2, {2, 6}},
                   {"start", C128, 2, {ANY, 7}}},
        .out = {{"end", C128, 2, {ROWS, 7}}, {"status", I32, 1, {ROWS}}, {"steps", I32, 1, {ROWS}},
                {"cond", F64, 1, {ROWS}}},
        .rows = 11, .nogil = 1, .run = run_track_slice,
        .error = "ik_track_slice: the problem is not valid (kinds 0, 1 or 4, 6 joints)",
    },
    [IK6R_ANGLES] = {
        .format = "OOOOOOO",
        .arrays = {{"x3", C128, 1, {ANY}}, {"vec", C128, 2, {N, 24}}, {"P", F64, 2, {14, 27}}, {"L", F64, 2, {14, 8}},
                   {"sigma", F64, 1, {3}}, {"dh", F64, 2, {6, 4}}, {"T", F64, 2, {4, 4}}},
        .out = {{"theta", C128, 2, {ROWS, 6}}},
        .run = run_ik6r_angles, .error = "ik6r_angles: failed",
    },
    [IK6R_SOLVE] = {
        .format = "OOOOO", /* kind, pair, dh, T, sigma */
        .arrays = {{"kind", I32, 1, {6}}, {"pair", F64, 2, {6, 2}}, {"dh", F64, 2, {6, 4}}, {"T", F64, 2, {4, 4}},
                   {"sigma", F64, 1, {3}}},
        .out = {{"theta", C128, 2, {16, 6}}},
        .nogil = 1, .prepare = prepare_ik6r_solve, .run = run_ik6r_solve,
        .error = "ik6r_solve: the problem is not six R-pairs",
    },
    [IK6R] = {
        .format = "OdOd", /* dh, scale, T, tol */
        .arrays = {{"dh", F64, 2, {6, 4}}, {"T", F64, 2, {4, 4}}},
        .out = {{"q", F64, 2, {16, 6}}, {"error", F64, 1, {16}}, {"found", I32, 1, {1}}, {"candidates", I32, 1, {1}}},
        .nogil = 1, .prepare = prepare_ik6r_solve, .run = run_ik6r,
        .error = "ik6r: a scale or tol not > 0",
    },
    [IK_NEWTON] = {
        .format = "OOOOOidddd", /* kind, pair, dh, p, theta, max_steps, tol, floor, stall, imag_max */
        .arrays = {{"kind", I32, 1, {6}}, {"pair", F64, 2, {6, 2}}, {"dh", F64, 2, {6, 4}}, {"p", C128, 1, {7}},
                   {"theta", C128, 2, {ANY, 6}}},
        .out = {{"theta", C128, 2, {ROWS, 6}}, {"size", F64, 1, {ROWS}}},
        .rows = 4, .nogil = 1, .run = run_newton,
        .error = "ik_newton: the problem is not valid (kinds 0, 1 or 4, 6 joints)",
    },
    [IK_LOCAL] = {
        .format = "OOOOOdOOdi", /* kind, pair, dh, lower, upper, scale, target, seed, tol, max_iter */
        .arrays = {{"kind", I32, 1, {ANY}}, {"pair", F64, 2, {N, 2}}, {"dh", F64, 2, {N, 4}}, {"lower", F64, 1, {N}},
                   {"upper", F64, 1, {N}}, {"target", F64, 3, {ANY, 4, 4}}, {"seed", F64, 2, {ANY, N}}},
        .out = {{"q", F64, 2, {ROWS, N}}, {"residual", F64, 1, {ROWS}}, {"converged", I32, 1, {ROWS}}},
        .rows = 7, .nogil = 1, .prepare = prepare_local, .run = run_local,
        .error = "ik_local: the chain is not valid (kinds 0 to 4; 1 to 7 joints)",
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
    [IK_WRIST] = {
        .format = "OdOd", /* dh, scale, target, tol */
        .arrays = {{"dh", F64, 2, {6, 4}}, {"target", F64, 3, {ANY, 4, 4}}},
        .out = {{"q", F64, 3, {ROWS, 8, 6}}, {"error", F64, 2, {ROWS, 8}}, {"found", I32, 1, {ROWS}},
                {"candidates", I32, 1, {ROWS}}, {"flags", I32, 1, {ROWS}}},
        .rows = 2, .nogil = 1, .run = run_wrist,
        .error = "ik_wrist: not a spherical wrist's twists, or a scale <= 0",
    },
    [IK_PARALLEL] = {
        .format = "OdOd", /* dh, scale, target, tol */
        .arrays = {{"dh", F64, 2, {6, 4}}, {"target", F64, 3, {ANY, 4, 4}}},
        .out = {{"q", F64, 3, {ROWS, 8, 6}}, {"error", F64, 2, {ROWS, 8}}, {"found", I32, 1, {ROWS}},
                {"candidates", I32, 1, {ROWS}}, {"flags", I32, 1, {ROWS}}},
        .rows = 2, .nogil = 1, .run = run_parallel,
        .error = "ik_parallel: axes 2, 3, 4 not parallel, axes 5 and 6 one line, or a scale <= 0",
    },
    [IK_THREE_PARALLEL] = {
        .format = "OdOd", /* dh, scale, target, tol */
        .arrays = {{"dh", F64, 2, {6, 4}}, {"target", F64, 3, {ANY, 4, 4}}},
        .out = {{"q", F64, 3, {ROWS, 8, 6}}, {"error", F64, 2, {ROWS, 8}}, {"found", I32, 1, {ROWS}},
                {"candidates", I32, 1, {ROWS}}, {"flags", I32, 1, {ROWS}}},
        .rows = 2, .nogil = 1, .run = run_three_parallel,
        .error = "ik_three_parallel: axes 1, 2, 3 not parallel, axes 5 and 6 not meeting, or a scale <= 0",
    },
    [IK_PARALLEL_APAIR] = {
        .format = "OOdOd", /* dh, amplitude, scale, target, tol */
        .arrays = {{"dh", F64, 2, {6, 4}}, {"amplitude", F64, 1, {6}}, {"target", F64, 3, {ANY, 4, 4}}},
        .out = {{"q", F64, 3, {ROWS, 32, 6}}, {"error", F64, 2, {ROWS, 32}}, {"found", I32, 1, {ROWS}},
                {"candidates", I32, 1, {ROWS}}, {"flags", I32, 1, {ROWS}}},
        .rows = 3, .nogil = 1, .run = run_parallel_apair,
        .error = "ik_parallel_apair: not a UR-like design with A-pairs at joint 3 or at joints 1 and 5, an amplitude < 0, "
                 "or a scale <= 0",
    },
    [IK_WRIST_APAIR] = {
        .format = "OOdOd", /* dh, amplitude, scale, target, tol */
        .arrays = {{"dh", F64, 2, {6, 4}}, {"amplitude", F64, 1, {6}}, {"target", F64, 3, {ANY, 4, 4}}},
        .out = {{"q", F64, 3, {ROWS, 32, 6}}, {"error", F64, 2, {ROWS, 32}}, {"found", I32, 1, {ROWS}},
                {"candidates", I32, 1, {ROWS}}, {"flags", I32, 1, {ROWS}}},
        .rows = 3, .nogil = 1, .run = run_wrist_apair,
        .error = "ik_wrist_apair: not a spherical-wrist design with axes 2 and 3 parallel and an A-pair at joint 3 "
                 "or 1, an amplitude <= 0, or a scale <= 0",
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
static PyObject *ik6r_solve(PyObject *m, PyObject *args) { return ik_marshal(m, IK6R_SOLVE, args); }
static PyObject *ik6r(PyObject *m, PyObject *args) { return ik_marshal(m, IK6R, args); }
static PyObject *ik_newton(PyObject *m, PyObject *args) { return ik_marshal(m, IK_NEWTON, args); }
static PyObject *ik_local(PyObject *m, PyObject *args) { return ik_marshal(m, IK_LOCAL, args); }
static PyObject *ik4_pencil(PyObject *m, PyObject *args) { return ik_marshal(m, IK4_PENCIL, args); }
static PyObject *ik4_screen(PyObject *m, PyObject *args) { return ik_marshal(m, IK4_SCREEN, args); }
static PyObject *ik4_left(PyObject *m, PyObject *args) { return ik_marshal(m, IK4_LEFT, args); }
static PyObject *ik_wrist(PyObject *m, PyObject *args) { return ik_marshal(m, IK_WRIST, args); }
static PyObject *ik_parallel(PyObject *m, PyObject *args) { return ik_marshal(m, IK_PARALLEL, args); }
static PyObject *ik_three_parallel(PyObject *m, PyObject *args) { return ik_marshal(m, IK_THREE_PARALLEL, args); }
static PyObject *ik_parallel_apair(PyObject *m, PyObject *args) { return ik_marshal(m, IK_PARALLEL_APAIR, args); }
static PyObject *ik_wrist_apair(PyObject *m, PyObject *args) { return ik_marshal(m, IK_WRIST_APAIR, args); }

/* ---- LocalIK: the single-pose fast path of AChain.ik_local
 *
 * call(T, q0, tol, max_iter) takes exactly what the validating path (apair.ik.local.ik_local)
 * accepts unchanged: T a float64 4 x 4 array (exactly an ndarray: no masked or other subclass),
 * finite, last row [0, 0, 0, 1] to its tolerances, rotation orthonormal with det +1; q0 a float64
 * (n,) array, finite, inside [lower, upper]; tol a float > 0, finite; max_iter an int in
 * [1, max_iter of the constructor]. Anything else, and a rotation orthonormal to less than
 * LOCAL_ORTHO (between it and the validating path's 1e-9 rounding could decide), returns None:
 * the caller then validates, and raises the one-line ValueError that names the argument, or
 * converts. So the two paths cannot disagree on what is an error, nor on the numbers. */

#define LOCAL_NMAX 7
#define LOCAL_ORTHO 0.5e-9          /* half of apair.ik.poses.check_matrix's tolerance 1e-9 */
#define LOCAL_LAST_TOL 1e-12        /* check_matrix: |last row - [0, 0, 0, 1]| <= 1e-12 ... */
#define LOCAL_LAST_TOL_ONE 1e-5     /* ... + 1e-5 for the 1 */

typedef struct {
    PyObject_HEAD
    int n;
    int kind[LOCAL_NMAX];
    double pair[2 * LOCAL_NMAX], dh[4 * LOCAL_NMAX], lower[LOCAL_NMAX], upper[LOCAL_NMAX], scale;
    long max_iter;    /* the largest max_iter accepted */
    PyObject *result; /* called with (q, residual, converged) */
} LocalIKObject;

static int local_traverse(LocalIKObject *self, visitproc visit, void *arg)
{
    Py_VISIT(self->result);
    return 0;
}

static int local_clear(LocalIKObject *self)
{
    Py_CLEAR(self->result);
    return 0;
}

static void local_dealloc(LocalIKObject *self)
{
    PyObject_GC_UnTrack(self);
    local_clear(self);
    Py_TYPE(self)->tp_free((PyObject *)self);
}

/* obj as a finite array of `type` and shape (n, cols) (cols 0: (n,)) copied into out: 0, or -1
 * with a ValueError naming it. n < 0: take n from obj and store it there. */
static int local_design(PyObject *obj, const char *name, int type, int *n, int cols, void *out)
{
    PyArrayObject *a = (PyArrayObject *)PyArray_FROM_OTF(obj, type, NPY_ARRAY_IN_ARRAY);
    int ok;
    if (a == NULL) {
        return -1;
    }
    if (*n < 0 && PyArray_NDIM(a) == 1) {
        *n = (int)(PyArray_DIM(a, 0) <= LOCAL_NMAX ? PyArray_DIM(a, 0) : LOCAL_NMAX + 1);
    }
    ok = *n >= 1 && *n <= LOCAL_NMAX && PyArray_NDIM(a) == (cols ? 2 : 1) && PyArray_DIM(a, 0) == *n &&
         (!cols || PyArray_DIM(a, 1) == cols);
    if (ok && type == NPY_DOUBLE) {
        const double *x = (const double *)PyArray_DATA(a);
        for (npy_intp k = 0; k < PyArray_SIZE(a); k++) {
            ok = ok && isfinite(x[k]);
        }
    }
    if (ok) {
        memcpy(out, PyArray_DATA(a), (size_t)PyArray_NBYTES(a));
    } else {
        PyErr_Format(PyExc_ValueError, "LocalIK: %s is not a finite array of shape (n%s) with 1 <= n <= %d", name,
                     cols == 2 ? ", 2" : cols == 4 ? ", 4" : ",", LOCAL_NMAX);
    }
    Py_DECREF(a);
    return ok ? 0 : -1;
}

/* LocalIK(kind, pair, dh, lower, upper, scale, max_iter, result): as ik_local takes them. */
static int local_init(LocalIKObject *self, PyObject *args, PyObject *kwds)
{
    PyObject *kind, *pair, *dh, *lower, *upper, *result;
    double scale;
    long max_iter;
    int n = -1;
    (void)kwds;
    if (!PyArg_ParseTuple(args, "OOOOOdlO", &kind, &pair, &dh, &lower, &upper, &scale, &max_iter, &result)) {
        return -1;
    }
    if (self->result != NULL) { /* call() reads the design without the GIL: it never changes */
        PyErr_SetString(PyExc_TypeError, "LocalIK: already initialised");
        return -1;
    }
    if (!PyCallable_Check(result)) {
        PyErr_SetString(PyExc_TypeError, "LocalIK: result must be callable");
        return -1;
    }
    if (local_design(kind, "kind", NPY_INT32, &n, 0, self->kind) || local_design(pair, "pair", NPY_DOUBLE, &n, 2, self->pair) ||
        local_design(dh, "dh", NPY_DOUBLE, &n, 4, self->dh) || local_design(lower, "lower", NPY_DOUBLE, &n, 0, self->lower) ||
        local_design(upper, "upper", NPY_DOUBLE, &n, 0, self->upper)) {
        return -1;
    }
    for (int i = 0; i < n; i++) {
        if (self->kind[i] < 0 || self->kind[i] > 4 || !(self->lower[i] <= self->upper[i])) {
            PyErr_Format(PyExc_ValueError, "LocalIK: joint %d has kind %d (0 to 4) and range (%g, %g)", i + 1,
                         self->kind[i], self->lower[i], self->upper[i]);
            return -1;
        }
    }
    if (!(scale > 0.0) || !isfinite(scale) || max_iter < 1 || max_iter > INT_MAX) {
        PyErr_SetString(PyExc_ValueError, "LocalIK: expected a finite scale > 0 and 1 <= max_iter <= INT_MAX");
        return -1;
    }
    self->n = n;
    self->scale = scale;
    self->max_iter = max_iter;
    Py_INCREF(result);
    self->result = result;
    return 0;
}

/* obj as a float64 array of exactly `size` doubles of shape (size,) or (4, 4) (nd), canonical
 * (native byte order, C-contiguous, aligned, an ndarray itself), copied into out: 1, else 0.
 * (Shared with ClosedIK, _native_closed.c.) */
int apair_native_canonical(PyObject *obj, int nd, npy_intp size, double *out)
{
    PyArrayObject *a = (PyArrayObject *)obj;
    if (!PyArray_CheckExact(obj) || PyArray_TYPE(a) != NPY_DOUBLE || !PyArray_ISNOTSWAPPED(a) ||
        !PyArray_IS_C_CONTIGUOUS(a) || !PyArray_ISALIGNED(a) || PyArray_NDIM(a) != nd || PyArray_SIZE(a) != size ||
        (nd == 2 && PyArray_DIM(a, 0) != 4)) {
        return 0;
    }
    memcpy(out, PyArray_DATA(a), sizeof(double) * (size_t)size);
    for (npy_intp k = 0; k < size; k++) {
        if (!isfinite(out[k])) {
            return 0;
        }
    }
    return 1;
}

/* Whether T (4 x 4, finite) is clearly a rigid transform by check_matrix's tests. */
int apair_native_rigid(const double *T)
{
    const double *R[3] = {T, T + 4, T + 8};
    double det;
    if (!(fabs(T[12]) <= LOCAL_LAST_TOL && fabs(T[13]) <= LOCAL_LAST_TOL && fabs(T[14]) <= LOCAL_LAST_TOL &&
          fabs(T[15] - 1.0) <= LOCAL_LAST_TOL + LOCAL_LAST_TOL_ONE)) {
        return 0;
    }
    for (int a = 0; a < 3; a++) {
        for (int b = 0; b < 3; b++) {
            double s = R[0][a] * R[0][b] + R[1][a] * R[1][b] + R[2][a] * R[2][b] - (a == b ? 1.0 : 0.0);
            if (!(fabs(s) <= LOCAL_ORTHO)) {
                return 0;
            }
        }
    }
    det = R[0][0] * (R[1][1] * R[2][2] - R[1][2] * R[2][1]) - R[0][1] * (R[1][0] * R[2][2] - R[1][2] * R[2][0]) +
          R[0][2] * (R[1][0] * R[2][1] - R[1][1] * R[2][0]);
    return det > 0.5; /* orthonormal to LOCAL_ORTHO: det is +-1 to about 1e-9 */
}

static PyObject *local_call(LocalIKObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    double T[16], q0[LOCAL_NMAX], tol;
    long max_iter;
    int overflow = 0, converged = 0, rc;
    npy_intp n = self->n;
    PyObject *out[3], *result;
    if (nargs != 4) {
        PyErr_SetString(PyExc_TypeError, "LocalIK.call(T, q0, tol, max_iter)");
        return NULL;
    }
    if (self->result == NULL) {
        PyErr_SetString(PyExc_RuntimeError, "LocalIK: not initialised");
        return NULL;
    }
    if (!apair_native_canonical(args[0], 2, 16, T) || !apair_native_rigid(T) || !apair_native_canonical(args[1], 1, n, q0) ||
        !PyFloat_Check(args[2]) || !PyLong_Check(args[3]) || PyBool_Check(args[3])) {
        Py_RETURN_NONE;
    }
    for (int i = 0; i < self->n; i++) {
        if (!(q0[i] >= self->lower[i] && q0[i] <= self->upper[i])) {
            Py_RETURN_NONE;
        }
    }
    tol = PyFloat_AS_DOUBLE(args[2]);
    max_iter = PyLong_AsLongAndOverflow(args[3], &overflow);
    if (!(tol > 0.0) || !isfinite(tol) || overflow || max_iter < 1 || max_iter > self->max_iter) {
        if (PyErr_Occurred()) {
            return NULL;
        }
        Py_RETURN_NONE;
    }
    out[0] = PyArray_SimpleNew(1, &n, NPY_DOUBLE);
    out[1] = PyArray_SimpleNew(0, NULL, NPY_DOUBLE);
    out[2] = PyArray_SimpleNew(0, NULL, NPY_BOOL);
    if (out[0] == NULL || out[1] == NULL || out[2] == NULL) {
        Py_XDECREF(out[0]);
        Py_XDECREF(out[1]);
        Py_XDECREF(out[2]);
        return NULL;
    }
    {
        const apair_ik_chain ch = {self->n, self->kind, self->pair, self->dh, self->lower, self->upper, self->scale};
        double *q = (double *)PyArray_DATA((PyArrayObject *)out[0]), *residual = (double *)PyArray_DATA((PyArrayObject *)out[1]);
        Py_BEGIN_ALLOW_THREADS
        rc = apair_ik_local(&ch, 1, T, 0, q0, (ptrdiff_t)self->n, tol, (int)max_iter, q, residual, &converged);
        Py_END_ALLOW_THREADS
    }
    *(npy_bool *)PyArray_DATA((PyArrayObject *)out[2]) = converged != 0;
    result = rc == 0 ? PyObject_Vectorcall(self->result, out, 3, NULL) : NULL;
    if (rc != 0) {
        PyErr_SetString(PyExc_ValueError, "ik_local: the chain is not valid (kinds 0 to 4; 1 to 7 joints)");
    }
    Py_DECREF(out[0]);
    Py_DECREF(out[1]);
    Py_DECREF(out[2]);
    return result;
}

static PyMethodDef local_methods[] = {
    {"call", (PyCFunction)(void (*)(void))local_call, METH_FASTCALL,
     "call(T, q0, tol, max_iter) -> result(q, residual, converged), or None when the inputs need the validating path."},
    {NULL, NULL, 0, NULL},
};

PyTypeObject apair_native_local_ik_type = {
    PyVarObject_HEAD_INIT(NULL, 0)
    .tp_name = "apair._native.LocalIK",
    .tp_basicsize = sizeof(LocalIKObject),
    .tp_dealloc = (destructor)local_dealloc,
    .tp_flags = Py_TPFLAGS_DEFAULT | Py_TPFLAGS_HAVE_GC,
    .tp_doc = "LocalIK(kind, pair, dh, lower, upper, scale, max_iter, result): the single-pose fast path of "
              "AChain.ik_local (apair.ik.local.local_solver).",
    .tp_traverse = (traverseproc)local_traverse,
    .tp_clear = (inquiry)local_clear,
    .tp_methods = local_methods,
    .tp_init = (initproc)local_init,
    .tp_new = PyType_GenericNew,
};

PyMethodDef apair_native_ik_methods[] = {
    {"ik_track_slice", ik_track_slice, METH_VARARGS,
     "ik_track_slice(kind, pair, dh, p, w, ell, dell, t0, dt, times_lambda, gamma, start) -> (end, status, steps, cond): "
     "apair_ik_track_slice."},
    {"ik_track", ik_track, METH_VARARGS,
     "ik_track(kind, pair, dh, p0, p1, gamma, start) -> (end, status, steps, cond): apair_ik_track."},
    {"ik6r_angles", ik6r_angles, METH_VARARGS,
     "ik6r_angles(x3, vec, P, L, sigma, dh, T) -> theta: apair_ik6r_angles."},
    {"ik6r_solve", ik6r_solve, METH_VARARGS,
     "ik6r_solve(kind, pair, dh, T, sigma) -> theta (16, 6), or None: apair_ik6r_solve (the 6R elimination, certified)."},
    {"ik6r", ik6r, METH_VARARGS,
     "ik6r(dh, scale, T, tol) -> (q (16, 6), error (16,), found (1,), candidates (1,)), or None: apair_ik6r."},
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
    {"ik_wrist", ik_wrist, METH_VARARGS,
     "ik_wrist(dh, scale, target, tol) -> (q, error, found, candidates, flags): apair_ik_wrist."},
    {"ik_parallel", ik_parallel, METH_VARARGS,
     "ik_parallel(dh, scale, target, tol) -> (q, error, found, candidates, flags): apair_ik_parallel."},
    {"ik_three_parallel", ik_three_parallel, METH_VARARGS,
     "ik_three_parallel(dh, scale, target, tol) -> (q, error, found, candidates, flags): apair_ik_three_parallel."},
    {"ik_parallel_apair", ik_parallel_apair, METH_VARARGS,
     "ik_parallel_apair(dh, amplitude (6,), scale, target, tol) -> (q, error, found, candidates, flags): "
     "apair_ik_parallel_apair."},
    {"ik_wrist_apair", ik_wrist_apair, METH_VARARGS,
     "ik_wrist_apair(dh, amplitude (6,), scale, target, tol) -> (q, error, found, candidates, flags): "
     "apair_ik_wrist_apair."},
    {NULL, NULL, 0, NULL},
};
