/*
 * A copy of src/csrc/apair_ik_local.c (hand-written), made by codegen/backends/c for the library in
 * generated/c. Do not edit: edit src/csrc/apair_ik_local.c. Content hash: 43524451f4e1e41c
 */
/*
 * A damped least-squares (Levenberg-Marquardt) local solver of inverse kinematics on fk<n> and
 * jacobian<n> (the kernels of derivations/chain_kinematics.py), each step projected onto the
 * joints' ranges (apair.ik.local). Hand-written C: the C backend of codegen copies it into
 * generated/c, the library it belongs to. Declared in apair.h (template:
 * codegen/backends/c/templates/apair.h.j2).
 */
#include "apair_ik_internal.h"

#define LOCAL_NMAX 7 /* the most joints of a chain for the local solver (NMAX, 6, is the trackers') */

#define LOCAL_INV_MAX 1024

/* The kernels of the local solver, with the design's invariants of fk and jacobian computed once. */
#define LOCAL_KINDS 5 /* revolute, sinusoidal, general, helical, prismatic */

typedef struct {
    const apair_kernel *fk, *jac, *laws[LOCAL_KINDS];
    double turning[LOCAL_NMAX]; /* dtheta/dq per joint: 0 for a prismatic pair */
    double inv_fk[LOCAL_INV_MAX], inv_jac[LOCAL_INV_MAX];
} local_kernels;

/* fk(q) (4 x 4) and, if J, the geometric Jacobian (6 x n); -1 outside a pair's range. */
static int chain_eval(const local_kernels *lk, const apair_ik_chain *ch, const double *q, double *T, double *J)
{
    double law[LOCAL_NMAX * 5];
    for (int i = 0; i < ch->n; i++) {
        const double *in[3] = {q + i, ch->pair + 2 * i, ch->pair + 2 * i + 1};
        double *out[1] = {law + 5 * i};
        lk->laws[ch->kind[i]]->eval(in, out);
        for (int k = 0; k < 5; k++)
            if (!isfinite(law[5 * i + k])) return -1;
    }
    const double *in[3] = {law, ch->dh, lk->turning};
    double *outT[1] = {T};
    if (lk->fk->n_invariants) lk->fk->core(lk->inv_fk, in, outT); else lk->fk->eval(in, outT);
    if (J) {
        double *outJ[1] = {J};
        if (lk->jac->n_invariants) lk->jac->core(lk->inv_jac, in, outJ); else lk->jac->eval(in, outJ);
    }
    return 0;
}

/* e = [(t_T - t) / scale; 1/2 sum_k R e_k x R_T e_k]: zero exactly at fk = T for rotations that
 * differ by less than pi; and the largest entry of |fk - T|. */
static double pose_error(const double *T, const double *target, double scale, double *e)
{
    double worst = 0.0;
    for (int k = 0; k < 12; k++) { double d = fabs(T[k] - target[k]); if (d > worst) worst = d; }
    for (int r = 0; r < 3; r++) e[r] = (target[4 * r + 3] - T[4 * r + 3]) / scale;
    e[3] = e[4] = e[5] = 0.0;
    for (int k = 0; k < 3; k++) {
        double a[3] = {T[k], T[4 + k], T[8 + k]}, b[3] = {target[k], target[4 + k], target[8 + k]};
        e[3] += 0.5 * (a[1] * b[2] - a[2] * b[1]);
        e[4] += 0.5 * (a[2] * b[0] - a[0] * b[2]);
        e[5] += 0.5 * (a[0] * b[1] - a[1] * b[0]);
    }
    return worst;
}

static double sq(const double *e) { double s = 0.0; for (int k = 0; k < 6; k++) s += e[k] * e[k]; return s; }

int apair_ik_local(const apair_ik_chain *ch, size_t count, const double *target, ptrdiff_t target_stride,
                   const double *seed, ptrdiff_t seed_stride, double tol, int max_iter, double *q, double *residual,
                   int *converged)
{
    static const char *fks[LOCAL_NMAX] = {"fk1", "fk2", "fk3", "fk4", "fk5", "fk6", "fk7"};
    static const char *jacs[LOCAL_NMAX] = {"jacobian1", "jacobian2", "jacobian3", "jacobian4", "jacobian5", "jacobian6",
                                              "jacobian7"};
    int n = ch->n;
    if (n < 1 || n > LOCAL_NMAX) return -1;
    local_kernels lk;
    lk.fk = apair_find_kernel(fks[n - 1]);
    lk.jac = apair_find_kernel(jacs[n - 1]);
    static const char *law_names[LOCAL_KINDS] = {"law_revolute", "law_sinusoidal", "law_general", "law_helical",
                                                 "law_prismatic"};
    for (int k = 0; k < LOCAL_KINDS; k++)
        if (!(lk.laws[k] = apair_find_kernel(law_names[k]))) return -1;
    if (!lk.fk || !lk.jac || lk.fk->n_invariants > LOCAL_INV_MAX || lk.jac->n_invariants > LOCAL_INV_MAX) return -1;
    for (int i = 0; i < n; i++) {
        if (ch->kind[i] < 0 || ch->kind[i] >= LOCAL_KINDS) return -1;
        lk.turning[i] = ch->kind[i] == 4 ? 0.0 : 1.0;
    }
    {
        const double *in[3] = {NULL, ch->dh, lk.turning};
        if (lk.fk->n_invariants) lk.fk->invariants(in, lk.inv_fk);
        if (lk.jac->n_invariants) lk.jac->invariants(in, lk.inv_jac);
    }
    for (size_t j = 0; j < count; j++) {
        const double *Tt = target + (ptrdiff_t)j * target_stride;
        double *x = q + j * n;
        double T[16], J[6 * LOCAL_NMAX], e[6], trial[LOCAL_NMAX], eT[6];
        for (int i = 0; i < n; i++) x[i] = fmin(fmax(seed[(ptrdiff_t)j * seed_stride + i], ch->lower[i]), ch->upper[i]);
        converged[j] = 0;
        residual[j] = INFINITY;
        if (chain_eval(&lk, ch, x, T, J)) continue;
        double err = pose_error(T, Tt, ch->scale, e), cost = sq(e), lambda = 1e-3;
        for (int it = 0; it < max_iter && err > tol; it++) {
            /* (J^T J + lambda diag(J^T J) + lambda 1e-9) dq = J^T e, J with its v rows in units of scale */
            double A[LOCAL_NMAX * LOCAL_NMAX], g[LOCAL_NMAX];
            for (int a = 0; a < n; a++) {
                g[a] = 0.0;
                for (int r = 0; r < 6; r++) g[a] += J[r * n + a] * (r < 3 ? 1.0 / ch->scale : 1.0) * e[r];
                for (int b = 0; b < n; b++) {
                    double s = 0.0;
                    for (int r = 0; r < 6; r++) {
                        double w = r < 3 ? 1.0 / (ch->scale * ch->scale) : 1.0;
                        s += J[r * n + a] * J[r * n + b] * w;
                    }
                    A[a * n + b] = s;
                }
            }
            int accepted = 0;
            for (int tries = 0; tries < 12 && !accepted; tries++) {
                double M[LOCAL_NMAX * LOCAL_NMAX], d[LOCAL_NMAX];
                memcpy(M, A, sizeof M);
                for (int a = 0; a < n; a++) M[a * n + a] += lambda * (A[a * n + a] + 1e-9);
                /* Cholesky M = L L^T, then the two triangular solves */
                int ok = 1;
                for (int a = 0; a < n && ok; a++) {
                    for (int b = 0; b <= a; b++) {
                        double s = M[a * n + b];
                        for (int k = 0; k < b; k++) s -= M[a * n + k] * M[b * n + k];
                        if (a == b) { if (!(s > 0.0)) { ok = 0; break; } M[a * n + a] = sqrt(s); }
                        else M[a * n + b] = s / M[b * n + b];
                    }
                }
                if (!ok) { lambda *= 10.0; continue; }
                for (int a = 0; a < n; a++) { double s = g[a]; for (int k = 0; k < a; k++) s -= M[a * n + k] * d[k]; d[a] = s / M[a * n + a]; }
                for (int a = n - 1; a >= 0; a--) { double s = d[a]; for (int k = a + 1; k < n; k++) s -= M[k * n + a] * d[k]; d[a] = s / M[a * n + a]; }
                for (int i = 0; i < n; i++) trial[i] = fmin(fmax(x[i] + d[i], ch->lower[i]), ch->upper[i]);
                double Tn[16], Jn[6 * LOCAL_NMAX];
                if (chain_eval(&lk, ch, trial, Tn, Jn) == 0) {
                    double errn = pose_error(Tn, Tt, ch->scale, eT), costn = sq(eT);
                    if (costn < cost || errn < err) {
                        memcpy(x, trial, n * sizeof(double));
                        memcpy(T, Tn, sizeof T);
                        memcpy(J, Jn, sizeof(double) * 6 * n);
                        memcpy(e, eT, sizeof e);
                        err = errn;
                        cost = costn;
                        lambda = fmax(lambda / 10.0, 1e-12);
                        accepted = 1;
                        break;
                    }
                }
                lambda *= 10.0;
            }
            if (!accepted) break;
        }
        residual[j] = err;
        converged[j] = err <= tol;
    }
    return 0;
}
