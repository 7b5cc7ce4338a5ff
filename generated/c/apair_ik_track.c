/*
 * A copy of src/csrc/apair_ik_track.c (hand-written), made by codegen/backends/c for the library in
 * generated/c. Do not edit: edit src/csrc/apair_ik_track.c. Content hash: 486939b727993f75
 */
/*
 * Path tracking of the homotopy system ik_system6 (all solutions of a pose, driven by
 * apair.ik.homotopy; the trace test's slice system too), with the residual in extended precision
 * far out in the complex, and Newton's method on ik_system6 at a fixed pose (apair.ik.elimination6r),
 * on the kernels of derivations/chain_ik.py. Hand-written C: the C backend of codegen copies it
 * into generated/c, the library it belongs to. Its functions are declared in apair.h (template:
 * codegen/backends/c/templates/apair.h.j2).
 */
#include "apair_ik_internal.h"

#define NV 7 /* variables of the trace test's slice system: the angles and lambda */
#define INV_MAX APAIR_IK_SYSTEM6_INVARIANTS /* the invariants of ik_system6 (apair.h) */
#define INV_RES APAIR_IK_RESIDUAL6_INVARIANTS
#define WIDE_STEP 1e-4 /* the step in tau below which a stall while tracking may turn extended precision on */
#define FAR 4.0 /* |Im theta| beyond which Newton's rounding floor in double may exceed the tracking tolerance */
#define ENDGAME 0.5       /* tau from which the endgame watches for a path to infinity (see to_infinity) */
#define ENDGAME_FAR 8.0   /* |Im theta| beyond which it may end a path (apair.ik.homotopy.tracker.ENDGAME_FAR) */
#define ENDGAME_RATIO 0.8 /* the most a path to infinity's slope may shrink from one sample to the next */
#define ENDGAME_SLOPE 0.1 /* the least outward slope of the farthest angle (per unit of log(1 - tau)) */
#define LN2 0.6931471805599453
#define KIND_A 1 /* the problem's joint kinds (apair_ik_problem): 0 an R-pair, 1 a sinusoidal A-pair, */
#define KIND_P 4 /* 4 a P-pair, whose variable is its slide x (law (1, 0, x, 1), turning factor 0) */

/* Solves A X = B for complex A and B (see GAUSS_SOLVE). */
GAUSS_SOLVE(csolve_m, cplx, cabs)

/* Solves A x = b (n x n, row-major, overwritten); b becomes x. */
static int csolve(int n, cplx *A, cplx *b) { return csolve_m(n, A, 1, b); }

/* The largest |x_i| (the max norm). */
static double cnorm(int n, const cplx *x)
{
    double m = 0.0;
    for (int i = 0; i < n; i++) { double a = cabs(x[i]); if (a > m) m = a; }
    return m;
}

/* ---------------------------------------------------------------- the homotopy */

typedef struct {
    const apair_ik_problem *pb;
    const apair_kernel *sys, *law[2];
    double inv[INV_MAX];
    double inv_res[INV_RES];          /* ik_residual6's invariants, for residual_wide */
    double h[NMAX];                   /* the amplitudes (0 for an R- or P-pair), ik_residual6's input */
    double turning[NMAX];             /* ik_system6's turning factors: 0 for a P-pair, else 1 */
    cplx p0[7], dp[7], gamma;
    int nv;                            /* variables: the n angles, or n + 1 with a slice */
    const apair_ik_slice *slice; /* NULL: H = F(theta; p(s)); else the slice system */
} tracker;

static cplx pair_at(const double *x, int k) { return x[2 * k] + I * x[2 * k + 1]; }

/* s(tau) = gamma tau / (1 + (gamma - 1) tau) and ds/dtau (if ds is not NULL). */
static cplx path_s(const tracker *tr, double tau, cplx *ds)
{
    cplx den = 1.0 + (tr->gamma - 1.0) * tau;
    if (ds) *ds = tr->gamma / (den * den);
    return tr->gamma * tau / den;
}

/* Coordinate k of the pose at v and s: p0 + s dp, or on a slice p + lambda w. */
static cplx pose_at(const tracker *tr, const cplx *v, cplx s, int k)
{
    const apair_ik_slice *sl = tr->slice;
    return sl ? pair_at(sl->p, k) + v[tr->pb->n] * pair_at(sl->w, k) : tr->p0[k] + s * tr->dp[k];
}

/* The slice's joint j at s: z = exp(i k theta_j) (k = 1/2 for an A-pair, 1 for an R-pair) and the
 * coefficients a, b of z and 1/z in l_s; for a P-pair z = x and b the coefficient of 1 (k = 0).
 * Returns k. */
static double slice_term(const tracker *tr, const cplx *v, cplx s, int j, cplx *z, cplx *a, cplx *b)
{
    const apair_ik_slice *sl = tr->slice;
    int n = tr->pb->n;
    int slide = tr->pb->kind[j] == KIND_P;
    double k = slide ? 0.0 : tr->pb->kind[j] == KIND_A ? 0.5 : 1.0;
    *z = slide ? v[j] : cexp(I * k * v[j]);
    *a = pair_at(sl->ell, j) + s * pair_at(sl->dell, j);
    *b = pair_at(sl->ell, n + j) + s * pair_at(sl->dell, n + j);
    return k;
}

/* H(theta, tau) = F(theta; p(s)) with p(s) = p0 + s (p1 - p0), s = gamma tau / (1 + (gamma - 1) tau);
 * Hv = dH/dtheta (n x n), Ht = dH/dtau; the law kernels take exp(i theta / 2), a P-pair's law is
 * (1, 0, x, 1) at its slide x = theta_i. With a slice, the slice system in (theta, lambda)
 * (nv x nv). Returns -1 if a value is not finite. */
static int eval(const tracker *tr, const cplx *v, double tau, cplx *H, cplx *Hv, cplx *Ht)
{
    const apair_ik_problem *pb = tr->pb;
    const apair_ik_slice *sl = tr->slice;
    int n = pb->n;
    double law[NMAX * 8];
    for (int i = 0; i < n; i++) {
        if (pb->kind[i] == KIND_P) {
            double out[8] = {1.0, 0.0, 0.0, 0.0, creal(v[i]), cimag(v[i]), 1.0, 0.0};
            memcpy(law + 8 * i, out, 8 * sizeof(double));
            continue;
        }
        cplx z = cexp(0.5 * I * v[i]);
        double vin[2] = {creal(z), cimag(z)}, out[8];
        const double *in[2] = {vin, pb->pair + 2 * i};
        double *outs[1] = {out};
        tr->law[pb->kind[i] == KIND_A]->eval(in, outs);
        memcpy(law + 8 * i, out, 8 * sizeof(double));
    }
    cplx ds, s = path_s(tr, tau, &ds);
    double target[14], dir[14];
    for (int k = 0; k < 7; k++) {
        /* on a slice the derivative is along w (F is linear in the pose) */
        cplx t = pose_at(tr, v, s, k), d = sl ? pair_at(sl->w, k) : tr->dp[k];
        target[2 * k] = creal(t);
        target[2 * k + 1] = cimag(t);
        dir[2 * k] = creal(d);
        dir[2 * k + 1] = cimag(d);
    }
    double F[12], dF[6 * NMAX * 2], dFs[12];
    const double *in[5] = {law, target, dir, pb->dh, tr->turning};
    double *out[3] = {F, dF, dFs};
    if (tr->sys->n_invariants)
        tr->sys->core(tr->inv, in, out);
    else
        tr->sys->eval(in, out);
    int nv = tr->nv;
    for (int r = 0; r < 6; r++) {
        H[r] = F[2 * r] + I * F[2 * r + 1];
        for (int i = 0; i < n; i++)
            Hv[r * nv + i] = dF[2 * (r * n + i)] + I * dF[2 * (r * n + i) + 1];
        if (sl) {
            Hv[r * nv + n] = dFs[2 * r] + I * dFs[2 * r + 1];
            Ht[r] = 0.0;
        } else {
            Ht[r] = (dFs[2 * r] + I * dFs[2 * r + 1]) * ds;
        }
    }
    if (sl) { /* the slice's last equation (l_s - 1) mu + t0 + s dt */
        cplx lam = v[n], mu = sl->times_lambda ? lam : 1.0, l = 0.0, dl = 0.0;
        for (int j = 0; j < n; j++) {
            cplx z, a, b;
            double k = slice_term(tr, v, s, j, &z, &a, &b);
            cplx zi = k ? 1.0 / z : 1.0; /* a P-pair's term is a x + b */
            l += a * z + b * zi;
            dl += pair_at(sl->dell, j) * z + pair_at(sl->dell, n + j) * zi;
            Hv[n * nv + j] = k ? I * k * (a * z - b * zi) * mu : a * mu;
        }
        H[n] = (l - 1.0) * mu + pair_at(sl->t0, 0) + s * pair_at(sl->dt, 0);
        Hv[n * nv + n] = sl->times_lambda ? l - 1.0 : 0.0;
        Ht[n] = (dl * mu + pair_at(sl->dt, 0)) * ds;
    }
    for (int r = 0; r < nv; r++)
        if (!isfinite(creal(H[r])) || !isfinite(cimag(H[r]))) return -1;
    return 0;
}

/* H of eval with the residual in extended precision (apair_wide): F from ik_residual6_wide at
 * z = exp(i theta / 2) (a P-pair: z = 1 and its slide), and the slice's equation summed in apair_wide. Far out in the complex the
 * terms of H that cancel are exp(2 |Im theta|) larger than H; in double, Newton stalls there. The
 * values z, the pose and the slice's coefficients are the double ones (H is exact at them). */
static int residual_wide(const tracker *tr, const cplx *v, double tau, cplx *H)
{
    const apair_ik_problem *pb = tr->pb;
    const apair_ik_slice *sl = tr->slice;
    int n = pb->n;
    apair_wide z[2 * NMAX], slide[2 * NMAX], target[14], F[12];
    for (int i = 0; i < n; i++) {
        int p = pb->kind[i] == KIND_P;
        cplx e = p ? 1.0 : cexp(0.5 * I * v[i]), x = p ? v[i] : 0.0;
        z[2 * i] = creal(e);
        z[2 * i + 1] = cimag(e);
        slide[2 * i] = creal(x);
        slide[2 * i + 1] = cimag(x);
    }
    cplx s = path_s(tr, tau, NULL);
    for (int k = 0; k < 7; k++) {
        cplx t = pose_at(tr, v, s, k);
        target[2 * k] = creal(t);
        target[2 * k + 1] = cimag(t);
    }
    apair_internal_ik_residual6_wide(tr->inv_res, z, slide, tr->h, target, pb->dh, F);
    for (int r = 0; r < 6; r++) H[r] = (double)F[2 * r] + I * (double)F[2 * r + 1];
    if (sl) { /* (l_s - 1) mu + t0 + s dt, l_s = sum a_j z_j + b_j / z_j */
        apair_wide lr = -1.0, li = 0.0;
        for (int j = 0; j < n; j++) {
            cplx e, a, b;
            double k = slice_term(tr, v, s, j, &e, &a, &b);
            apair_wide zr = creal(e), zi = cimag(e), m = zr * zr + zi * zi;
            apair_wide ar = creal(a), ai = cimag(a), br = creal(b), bi = cimag(b);
            lr += ar * zr - ai * zi + (k ? (br * zr + bi * zi) / m : br); /* b / z = b conj(z) / |z|^2; a P-pair's b */
            li += ar * zi + ai * zr + (k ? (bi * zr - br * zi) / m : bi);
        }
        cplx mu = sl->times_lambda ? v[n] : 1.0, c = pair_at(sl->t0, 0) + s * pair_at(sl->dt, 0);
        apair_wide mr = creal(mu), mi = cimag(mu);
        H[n] = (double)(lr * mr - li * mi + (apair_wide)creal(c)) + I * (double)(lr * mi + li * mr + (apair_wide)cimag(c));
    }
    for (int r = 0; r < tr->nv; r++)
        if (!isfinite(creal(H[r])) || !isfinite(cimag(H[r]))) return -1;
    return 0;
}

/* How far out joint i's variable is: |Im theta| of an angle; log |x| (0 within |x| <= 1) of a
 * P-pair's slide x, which goes to infinity as exp(i theta / 2) goes to 0 or infinity. */
static double joint_far(const tracker *tr, const cplx *v, int i)
{
    return tr->pb->kind[i] == KIND_P ? fmax(0.0, log(cabs(v[i]))) : fabs(cimag(v[i]));
}

/* The farthest out of a point's joints (joint_far; lambda is no joint). */
static double far_of(const tracker *tr, const cplx *v)
{
    double far = 0.0;
    for (int i = 0; i < tr->pb->n; i++) far = fmax(far, joint_far(tr, v, i));
    return far;
}

/* dv/dtau at (v, tau): Hv v' = -Ht. */
static int tangent(const tracker *tr, const cplx *v, double tau, cplx *k)
{
    int n = tr->nv;
    cplx H[NV], Hv[NV * NV], Ht[NV];
    if (eval(tr, v, tau, H, Hv, Ht)) return -1;
    for (int i = 0; i < n; i++) k[i] = -Ht[i];
    return csolve(n, Hv, k);
}

/* Newton's method on H(., tau) from v (updated in place): 1 if ||dv|| <= tol (1 + ||v||) within
 * `iters` steps, each at most half the one before. *last: the last step's size. k (if not NULL):
 * the tangent dv/dtau at the last point evaluated, from the same factorisation (that point is
 * within the last step of v, so the next predictor step can start from it). *wide: whether the
 * residual is taken in extended precision; a step that stalls far out (|Im theta| > far_wide)
 * above 1e3 tol turns it on, and two more steps are granted (the Jacobian stays double: its
 * relative error is far below 1, so Newton still converges, to the double rounding of v). */
static int correct(const tracker *tr, cplx *v, double tau, int iters, double tol, double far_wide, double *last,
                   cplx *k, int *wide)
{
    int n = tr->nv;
    double prev = INFINITY;
    for (int it = 0; it < iters; it++) {
        cplx H[NV], Hv[NV * NV], Ht[NV], B[2 * NV];
        if (eval(tr, v, tau, H, Hv, Ht)) return 0;
        if (*wide && residual_wide(tr, v, tau, H)) return 0;
        for (int i = 0; i < n; i++) { B[2 * i] = -H[i]; B[2 * i + 1] = -Ht[i]; }
        if (csolve_m(n, Hv, 2, B)) return 0;
        for (int i = 0; i < n; i++) H[i] = B[2 * i];
        if (k)
            for (int i = 0; i < n; i++) k[i] = B[2 * i + 1];
        double d = cnorm(n, H);
        for (int i = 0; i < n; i++) v[i] += H[i];
        *last = d;
        if (d <= tol * (1.0 + cnorm(n, v))) return 1;
        if (it > 0 && d > 0.5 * prev) {
            /* Newton stalls at the rounding floor: far out the products of cos and sin of theta
             * that cancel in H are exp(2 |Im theta|) large. Keep tracking there if the floor is
             * small (the endpoint must still meet the strict tolerance), else go on in extended
             * precision. */
            double far = far_of(tr, v);
            if (!*wide && far > FAR && d <= 1e3 * tol * (1.0 + cnorm(n, v))) return 1;
            if (*wide || !(far > far_wide)) return 0;
            *wide = 1;
            iters = it + 3;
        }
        prev = d;
    }
    return 0;
}

/* 1-norm condition number of Hv at (v, 1), from its inverse. */
static double condition(const tracker *tr, const cplx *v)
{
    int n = tr->nv;
    cplx H[NV], Hv[NV * NV], Ht[NV], A[NV * NV];
    if (eval(tr, v, 1.0, H, Hv, Ht)) return INFINITY;
    double norm = 0.0, inorm = 0.0;
    for (int c = 0; c < n; c++) {
        double s = 0.0;
        for (int r = 0; r < n; r++) s += cabs(Hv[r * n + c]);
        if (s > norm) norm = s;
    }
    for (int c = 0; c < n; c++) {
        cplx e[NV];
        for (int r = 0; r < n; r++) e[r] = 0.0;
        e[c] = 1.0;
        memcpy(A, Hv, sizeof(cplx) * n * n);
        if (csolve(n, A, e)) return INFINITY;
        double s = 0.0;
        for (int r = 0; r < n; r++) s += cabs(e[r]);
        if (s > inorm) inorm = s;
    }
    return norm * inorm;
}

/* Whether the endpoint v (at tau = 1, far out) is a regular root although Hv's condition number
 * is large. In the angles the condition number of a point far out is large at regular roots too
 * (the values that cancel in H are exp(2 |Im theta|) large), so the test is Newton's: from v moved
 * by 1e-7 (1 + ||v||), four steps with the residual in extended precision must come back to v to
 * final_tol. They do when the convergence is quadratic; at a multiple root it is linear (each step
 * about half the one before, at a double root). */
static int regular_far(const tracker *tr, const apair_ik_options *opt, const cplx *v)
{
    int n = tr->nv, wide = 1;
    double size = 1.0 + cnorm(n, v), d = INFINITY;
    cplx q[NV], e[NV];
    for (int i = 0; i < n; i++) q[i] = v[i] + 1e-7 * size * ((i % 2) ? 1.0 : I);
    for (int it = 0; it < 4 && !(d <= opt->final_tol * size); it++)
        if (!correct(tr, q, 1.0, 1, opt->final_tol, 0.0, &d, NULL, &wide) && !isfinite(d)) return 0;
    for (int i = 0; i < n; i++) e[i] = q[i] - v[i];
    return d <= opt->final_tol * size && cnorm(n, e) <= 1e-10 * size;
}

/* The endgame's samples of one path: the last one (L = log(1 - tau), the angles, a P-pair's slide
 * x as the angle i log x, continued from sample to sample, and x itself) and the slope over the
 * interval that ended there. */
typedef struct {
    int samples;
    double L;
    cplx v[NMAX], x[NMAX], beta[NMAX];
} endgame;

/* Whether the path is going to infinity (an endgame in L = log(1 - tau), from tau >= ENDGAME). Near
 * the end of a path each exp(i theta / 2) has a Puiseux series in 1 - tau: on a path to infinity
 * theta is asymptotically affine in L (theta = alpha + beta L, beta a rational multiple of i), while
 * on a path to a finite point the slope dtheta/dL tends to 0 in a fixed direction, by 2^(-1/c) per
 * halving of 1 - tau (c its cycle number). A sample is taken each time L has dropped by ln 2, and
 * the slope of the farthest angle theta_j since the last one, beta, compared with the one before,
 * beta0. Going to infinity: theta_j moves outward (|Im theta_j| grows) at ENDGAME_SLOPE or more, in
 * the same direction (|beta - beta0| <= |beta| / 2), neither that motion nor |beta| shrank by more
 * than r = ENDGAME_RATIO (a path to a finite point passes only before its series governs it, or
 * with c >= 4), and |Im theta_j| exceeds ENDGAME_FAR and |beta| ln 2 r / (1 - r), the most a slope
 * shrinking by r per halving could still move it. Such a path ends at infinity or at a finite point
 * farther out, which double precision cannot tell apart: apair.ik.homotopy.endpoints takes the
 * paths of a pose that end beyond ENDGAME_FAR alike, none of them real. The angles only (not the
 * slice system's lambda). */
static int to_infinity(endgame *eg, const tracker *tr, const cplx *v, double tau)
{
    int n = tr->pb->n;
    if (tau < ENDGAME || tau >= 1.0) return 0;
    double L = log1p(-tau);
    if (eg->samples && eg->L - L < LN2) return 0;
    int verdict = 0;
    cplx c[NMAX]; /* the angles, a P-pair's slide as i log x (Im: log |x|) */
    for (int i = 0; i < n; i++)
        c[i] = tr->pb->kind[i] != KIND_P ? v[i] : eg->samples ? eg->v[i] + I * clog(v[i] / eg->x[i]) : I * clog(v[i]);
    if (eg->samples) {
        cplx beta[NMAX];
        double far = -1.0;
        int j = 0;
        for (int i = 0; i < n; i++) {
            beta[i] = (c[i] - eg->v[i]) / (L - eg->L);
            if (joint_far(tr, v, i) > far) { far = joint_far(tr, v, i); j = i; }
        }
        if (eg->samples >= 2 && far > ENDGAME_FAR) {
            double sign = cimag(c[j]) > 0 ? -1.0 : 1.0; /* outward: |Im theta_j| grows as L drops */
            double out = sign * cimag(beta[j]), out0 = sign * cimag(eg->beta[j]), size = cabs(beta[j]);
            double reach = size * LN2 * ENDGAME_RATIO / (1.0 - ENDGAME_RATIO);
            verdict = out >= ENDGAME_SLOPE && out >= ENDGAME_RATIO * out0 && cabs(beta[j] - eg->beta[j]) <= 0.5 * size &&
                      size >= ENDGAME_RATIO * cabs(eg->beta[j]) && far > reach;
        }
        memcpy(eg->beta, beta, n * sizeof(cplx));
    }
    eg->L = L;
    memcpy(eg->v, c, n * sizeof(cplx));
    memcpy(eg->x, v, n * sizeof(cplx));
    eg->samples++;
    return verdict;
}

/* One path from tau = 0 to 1: RK4 predictor, Newton corrector, step size halved on failure and
 * grown after successes; at tau = 1 Newton to full accuracy. A step costs four evaluations plus
 * the corrector's: its first stage is the last corrector iteration's tangent. Where far-out
 * endpoints are of no interest (wide_end infinite: the paths of one pose, never refined there), a
 * path found going to infinity (to_infinity) ends DIVERGED long before |Im theta| reaches
 * `divergence`, where each step needs extended precision; the start sets and the trace test, whose
 * endpoints are all finite, are tracked without it. */
static int track_path(const tracker *tr, const apair_ik_options *opt, cplx *v, int *steps, double *cond)
{
    int n = tr->nv;
    double tau = 0.0, h = opt->initial_step, last = 0.0;
    int good = 0, have_k1 = 0, wide = 0, wide_steps = 0;
    endgame eg;
    eg.samples = 0;
    int endgame_on = !(opt->wide_end < INFINITY);
    cplx k1[NV];  /* dv/dtau at (v, tau): kept across a failed step, taken from the corrector after one */
    *steps = 0;
    *cond = INFINITY;
    while (tau < 1.0) {
        if (++*steps > opt->max_steps) return APAIR_PATH_TOO_LONG;
        double hh = fmin(h, 1.0 - tau);
        cplx k2[NV], k3[NV], k4[NV], w[NV], p[NV], knext[NV];
        int ok = have_k1 || tangent(tr, v, tau, k1) == 0;
        have_k1 = ok;
        if (ok) { for (int i = 0; i < n; i++) w[i] = v[i] + 0.5 * hh * k1[i]; ok = tangent(tr, w, tau + 0.5 * hh, k2) == 0; }
        if (ok) { for (int i = 0; i < n; i++) w[i] = v[i] + 0.5 * hh * k2[i]; ok = tangent(tr, w, tau + 0.5 * hh, k3) == 0; }
        if (ok) { for (int i = 0; i < n; i++) w[i] = v[i] + hh * k3[i]; ok = tangent(tr, w, tau + hh, k4) == 0; }
        if (ok) {
            for (int i = 0; i < n; i++) p[i] = v[i] + hh / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
            /* extended precision only once the step has shrunk: most stalls far out are steps too long */
            ok = correct(tr, p, tau + hh, opt->corrector_steps, opt->path_tol, hh < WIDE_STEP ? opt->wide_track : INFINITY,
                         &last, knext, &wide);
            /* a path that crawls far out (each step in extended precision, the predictor's double
             * tangents too inexact for long steps) is given up: with a new gamma it takes another way */
            if (wide && ++wide_steps > opt->wide_steps) return APAIR_PATH_TOO_LONG;
        }
        if (ok) {
            memcpy(v, p, n * sizeof(cplx));
            double far = far_of(tr, v);
            if (!(far > opt->wide_track)) wide = 0;
            memcpy(k1, knext, n * sizeof(cplx));  /* the next step's first stage, from the corrector */
            tau = (hh == 1.0 - tau) ? 1.0 : tau + hh;
            if (++good >= 2) { h = fmin(2.0 * h, opt->max_step); good = 0; }
            if (far > opt->divergence || (endgame_on && to_infinity(&eg, tr, v, tau))) return APAIR_PATH_DIVERGED;
        } else {
            h *= 0.5;
            good = 0;
            if (h < opt->min_step) return APAIR_PATH_FAILED;
        }
    }
    /* the endpoint: Newton at tau = 1 until its step stops shrinking (or reaches final_tol); far
     * out, once it stalls, on with the residual in extended precision */
    double prev = INFINITY;
    for (int it = 0; it < opt->final_steps; it++) {
        double d = INFINITY;
        cplx q[NV];
        memcpy(q, v, n * sizeof(cplx));
        int done = correct(tr, q, 1.0, 1, opt->final_tol, opt->wide_end, &d, NULL, &wide);
        if (!isfinite(d)) break;
        if (d >= prev) {
            if (wide || !(far_of(tr, v) > opt->wide_end)) break;
            wide = 1;
            prev = INFINITY;
            continue;
        }
        memcpy(v, q, n * sizeof(cplx));
        prev = d;
        if (done) break;
    }
    int converged = prev <= opt->path_tol * (1.0 + cnorm(n, v));
    *cond = condition(tr, v);
    for (int i = 0; i < n; i++)
        if (!isfinite(creal(v[i])) || !isfinite(cimag(v[i]))) return APAIR_PATH_DIVERGED;
    double far = far_of(tr, v);
    if (far > opt->divergence) return APAIR_PATH_DIVERGED;
    if (!converged || (*cond > opt->singular_cond && !(far > opt->wide_end && regular_far(tr, opt, v))))
        return APAIR_PATH_SINGULAR;
    return APAIR_PATH_OK;
}

void apair_ik_default_options(apair_ik_options *opt)
{
    opt->initial_step = 0.1;
    opt->max_step = 0.5;
    opt->min_step = 1e-12;
    opt->max_steps = 500;
    opt->corrector_steps = 3;
    opt->path_tol = 1e-7;
    opt->final_tol = 1e-14;
    opt->final_steps = 30;
    opt->divergence = 40.0;
    opt->singular_cond = 1e10;
    opt->wide_track = 4.0;
    opt->wide_end = 4.0;
    opt->wide_steps = 500;
}

/* The tracker of problem pb from the pose p0 to p1 (7 complex each, as 14 doubles) with gamma:
 * its kernels, and the design's invariants computed once. Returns 0, or -1 for a bad problem. */
static int setup(tracker *tr, const apair_ik_problem *pb, const double *p0, const double *p1, cplx gamma)
{
    if (pb->n != NMAX) return -1;
    tr->pb = pb;
    tr->sys = apair_find_kernel("ik_system6");
    tr->law[0] = apair_find_kernel("ik_law_revolute");
    tr->law[1] = apair_find_kernel("ik_law_sinusoidal");
    if (!tr->sys || !tr->law[0] || !tr->law[1] || tr->sys->n_invariants > INV_MAX) return -1;
    for (int i = 0; i < pb->n; i++) {
        if (pb->kind[i] != 0 && pb->kind[i] != KIND_A && pb->kind[i] != KIND_P) return -1;
        tr->h[i] = pb->kind[i] == KIND_A ? pb->pair[2 * i] : 0.0;
        tr->turning[i] = pb->kind[i] == KIND_P ? 0.0 : 1.0;
    }
    if (tr->sys->n_invariants) {
        const double *in[5] = {NULL, NULL, NULL, pb->dh, tr->turning};
        tr->sys->invariants(in, tr->inv);
    }
    apair_ik_residual6_invariants(tr->h, pb->dh, tr->inv_res);
    for (int k = 0; k < 7; k++) {
        tr->p0[k] = p0[2 * k] + I * p0[2 * k + 1];
        tr->dp[k] = (p1[2 * k] + I * p1[2 * k + 1]) - tr->p0[k];
    }
    tr->gamma = gamma;
    tr->nv = pb->n;
    tr->slice = NULL;
    return 0;
}

/* Tracks every start point from s = 0 to 1 with the tracker tr, end/status/steps/cond per path. */
static void track_all(const tracker *tr, const apair_ik_options *opt, size_t count, const double *start,
                      double *end, int *status, int *steps, double *cond)
{
    int n = tr->nv;
    for (size_t j = 0; j < count; j++) {
        cplx v[NV];
        for (int i = 0; i < n; i++) v[i] = start[2 * (j * n + i)] + I * start[2 * (j * n + i) + 1];
        status[j] = track_path(tr, opt, v, steps + j, cond + j);
        for (int i = 0; i < n; i++) {
            end[2 * (j * n + i)] = creal(v[i]);
            end[2 * (j * n + i) + 1] = cimag(v[i]);
        }
    }
}

int apair_ik_track(const apair_ik_problem *pb, const apair_ik_options *opt, const double *p0,
                   const double *p1, const double *gamma, size_t count, const double *start, double *end,
                   int *status, int *steps, double *cond)
{
    tracker tr;
    if (setup(&tr, pb, p0, p1, gamma[0] + I * gamma[1])) return -1;
    track_all(&tr, opt, count, start, end, status, steps, cond);
    return 0;
}

int apair_ik_track_slice(const apair_ik_problem *pb, const apair_ik_options *opt,
                         const apair_ik_slice *sl, const double *gamma, size_t count, const double *start,
                         double *end, int *status, int *steps, double *cond)
{
    tracker tr;
    if (setup(&tr, pb, sl->p, sl->p, gamma[0] + I * gamma[1])) return -1;
    tr.nv = pb->n + 1;
    tr.slice = sl;
    track_all(&tr, opt, count, start, end, status, steps, cond);
    return 0;
}

int apair_ik_newton(const apair_ik_problem *pb, const double *p, size_t count, double *theta, int max_steps,
                    double tol, double floor, double stall, double imag_max, double *size)
{
    tracker tr;
    if (setup(&tr, pb, p, p, 1.0)) return -1;
    int n = pb->n;
    for (size_t j = 0; j < count; j++) {
        cplx v[NMAX];
        double d = INFINITY, prev = INFINITY;
        for (int i = 0; i < n; i++) v[i] = theta[2 * (j * n + i)] + I * theta[2 * (j * n + i) + 1];
        for (int it = 0; it < max_steps; it++) {
            cplx H[NMAX], Hv[NMAX * NMAX], Ht[NMAX];
            if (eval(&tr, v, 1.0, H, Hv, Ht) || csolve(n, Hv, H)) { d = INFINITY; break; }
            prev = d;
            d = cnorm(n, H);
            int out = !isfinite(d);
            for (int i = 0; i < n; i++) {
                v[i] -= H[i];
                out |= !(fabs(cimag(v[i])) <= imag_max);
            }
            if (out) { d = INFINITY; break; }
            if (d <= tol || (d <= floor && d > stall * prev)) break;  /* converged, or at its rounding floor */
        }
        size[j] = d;
        for (int i = 0; i < n; i++) {
            theta[2 * (j * n + i)] = creal(v[i]);
            theta[2 * (j * n + i) + 1] = cimag(v[i]);
        }
    }
    return 0;
}
