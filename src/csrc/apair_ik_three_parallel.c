/*
 * The closed-form inverse kinematics of six-joint R-chains with axes 1, 2 and 3 parallel and axes 5
 * and 6 meeting (apair.ik.three_parallel, where the steps are explained): the derived kernel
 * ik_three_parallel6 (derivations/chain_ik_three_parallel.py) gives W, where axes 5 and 6 meet,
 * A cos psi_4 + B sin psi_4 = C from its height along the parallel axes, the third row u(psi_4) of
 * A_1 A_2 A_3 A_4's rotation and g, the third row of R_6 Rx(alpha_6)^T; psi_4 (two), psi_5 (two, from
 * the third entry of u Rz(psi_5) Rx(alpha_5) = g Rz(psi_6)^T), psi_6, the sum of the parallel joints'
 * angles and the planar elbow (two) follow in closed form, and each candidate gets up to two
 * Gauss-Newton steps and is kept where fk reproduces the pose to tol (apair_ik_closed.h). Hand-written
 * C: the C backend of codegen copies it into generated/c. Declared in apair.h.
 */
#include "apair_ik_closed.h"

typedef struct {
    closed_fk k;
    double dh[24], scale, e1, e12, ca[6], sa[6], phi[6];
    double inv_pos[CLOSED_INV_MAX];
} three_design;

/* the prepared design lives in apair_ik_closed's storage */
typedef char three_design_fits[sizeof(three_design) <= sizeof(((apair_ik_closed *)0)->design) ? 1 : -1];

int apair_ik_three_parallel_prepare(void *design, const double *dh, double scale)
{
    three_design *p = (three_design *)design;
    if (closed_fk_init(&p->k, dh) || !(scale > 0) || APAIR_IK_THREE_PARALLEL6_INVARIANTS > CLOSED_INV_MAX) return -1;
    memcpy(p->dh, dh, sizeof p->dh);
    p->scale = scale;
    apair_ik_three_parallel6_invariants(dh, p->inv_pos);
    for (int i = 0; i < 6; i++) { p->ca[i] = cos(dh[4 * i + 1]); p->sa[i] = sin(dh[4 * i + 1]); p->phi[i] = dh[4 * i + 3]; }
    p->e1 = p->ca[0];
    p->e12 = p->ca[0] * p->ca[1];
    double flat = CLOSED_FLAT * scale;
    if (fabs(p->sa[0]) > CLOSED_FLAT || fabs(p->sa[1]) > CLOSED_FLAT) return -1; /* axes 1, 2, 3 not parallel */
    if (fabs(dh[16]) > flat || fabs(p->sa[4]) <= CLOSED_FLAT) return -1;          /* axes 5 and 6 do not meet */
    if (fabs(dh[0]) <= flat || fabs(dh[4]) <= flat) return -1;                     /* two of axes 1-3 on one line */
    /* psi_4 must move W along the parallel axes: A = -c_5 e sin(alpha_3) sin(alpha_4), B = a_4 e sin(alpha_3) */
    if (hypot(dh[18] * p->sa[3], dh[12]) * fabs(p->sa[2]) <= flat) return -1;
    return 0;
}

/* x with a cos x + b sin x = c: 0, 1 (tangent) or 2 solutions; -1 where a = b = 0 against ref */
static int lin_trig(double a, double b, double c, double ref, double *x)
{
    double r = hypot(a, b);
    if (!(r > CLOSED_FLAT * ref)) return -1;
    double k = c / r;
    if (!(fabs(k) <= 1 + 1e-6)) return 0;
    double base = atan2(b, a), d = acos(fmin(1.0, fmax(-1.0, k)));
    if (d <= CLOSED_SINGULAR) { x[0] = base; return 1; }
    if (d >= CLOSED_PI - CLOSED_SINGULAR) { x[0] = base + CLOSED_PI; return 1; }
    x[0] = base + d;
    x[1] = base - d;
    return 2;
}

/* N = A_1 A_2 A_3 = T (A_4 A_5 A_6)^-1 (3 x 4) at psi_4, psi_5, psi_6 */
static void frame3(const three_design *p, const double *Tt, const double *psi456, double *N)
{
    const double *dh = p->dh;
    double M[12], A[12], Mi[12];
    closed_dh4(dh[12], p->ca[3], p->sa[3], dh[14], psi456[0], M);
    closed_dh4(dh[16], p->ca[4], p->sa[4], dh[18], psi456[1], A);
    closed_mul34(M, A, M);
    closed_dh4(dh[20], p->ca[5], p->sa[5], dh[22], psi456[2], A);
    closed_mul34(M, A, M);
    for (int r = 0; r < 3; r++) {
        for (int k = 0; k < 3; k++) Mi[4 * r + k] = M[4 * k + r];
        Mi[4 * r + 3] = -(M[r] * M[3] + M[4 + r] * M[7] + M[8 + r] * M[11]);
    }
    double T34[12] = {Tt[0], Tt[1], Tt[2], Tt[3], Tt[4], Tt[5], Tt[6], Tt[7], Tt[8], Tt[9], Tt[10], Tt[11]};
    closed_mul34(T34, Mi, N);
}

/* P = frame 3's origin less a_3 (cos S, sin S) in the base plane (S = psi_1 + e1 psi_2 + e12 psi_3, read
 * off N's first column): P = a_1 e(psi_1) + a_2 e(psi_1 + e1 psi_2) */
static double planar(const three_design *p, const double *N, double *P)
{
    double S = atan2(N[4], N[0]);
    P[0] = N[3] - p->dh[8] * cos(S);
    P[1] = N[7] - p->dh[8] * sin(S);
    return S;
}

/* Where joint 5 or 6 turns freely (its axis parallel to axes 1-3, four parallel joints: a
 * self-motion), P runs on a circle as it turns, |P|^2 = A + B cos x + C sin x; the member taken has
 * the elbow at cos psi_2 = 0 (|P|^2 = a_1^2 + a_2^2) where the circle reaches it, else the nearest. */
static double free_member(const three_design *p, const double *Tt, double *psi456, int which)
{
    double N[12], P[2], r[3];
    for (int k = 0; k < 3; k++) {
        psi456[which] = k * CLOSED_PI / 2;
        frame3(p, Tt, psi456, N);
        planar(p, N, P);
        r[k] = P[0] * P[0] + P[1] * P[1];
    }
    double A = 0.5 * (r[0] + r[2]), B = 0.5 * (r[0] - r[2]), C = r[1] - A, K = hypot(B, C);
    double mid = p->dh[0] * p->dh[0] + p->dh[4] * p->dh[4];
    if (!(K > CLOSED_FLAT * mid)) return 0.0;
    return atan2(C, B) + acos(fmin(1.0, fmax(-1.0, (mid - A) / K)));
}

/* the elbows (at most 2) of the planar problem left by psi_4, psi_5, psi_6: candidates x = psi - phi */
static int elbows(const three_design *p, const double *Tt, const double *psi456, double *x, int *flags)
{
    double N[12], P[2];
    frame3(p, Tt, psi456, N);
    double S = planar(p, N, P), a1 = p->dh[0], a2 = p->dh[4], rho2 = P[0] * P[0] + P[1] * P[1];
    double c2 = (rho2 - a1 * a1 - a2 * a2) / (2 * a1 * a2);
    if (!(fabs(c2) <= 1 + 1e-6)) return 0;
    double rest = 1 - c2 * c2, s2 = rest <= 4 * CLOSED_DOUBLE ? 0.0 : sqrt(rest);
    int n = 0;
    for (int s = 0; s < (s2 > 0 ? 2 : 1); s++) {
        double g = atan2(s ? -s2 : s2, c2), psi1; /* g = e1 psi_2 */
        if (rho2 <= (CLOSED_FLAT * p->scale) * (CLOSED_FLAT * p->scale)) { *flags |= 4; psi1 = 0.0; }
        else psi1 = atan2(P[1], P[0]) - atan2(a2 * sin(g), a1 + a2 * cos(g));
        double psi[6] = {psi1, p->e1 * g, p->e12 * (S - psi1 - g), psi456[0], psi456[1], psi456[2]};
        for (int i = 0; i < 6; i++) x[6 * n + i] = closed_wrap(psi[i] - p->phi[i]);
        n++;
    }
    return n;
}

void apair_ik_three_parallel_solve1(const void *design, const double *Tt, double tol, double *qj, double *ej,
                                    int *found, int *candidates, int *flags)
{
    const three_design *p = (const three_design *)design;
    double W[3], F4[3], U[9], g[3], psi4s[2];
    *found = *candidates = *flags = 0;
    apair_ik_three_parallel6_core(p->inv_pos, p->dh, Tt, W, F4, U, g);
    int n4 = lin_trig(F4[0], F4[1], F4[2], p->scale, psi4s);
    double ca5 = p->ca[4], sa5 = p->sa[4];
    for (int k4 = 0; k4 < n4; k4++) {
        double c4 = cos(psi4s[k4]), s4 = sin(psi4s[k4]), u[3], psi5s[2];
        for (int k = 0; k < 3; k++) u[k] = U[3 * k] + U[3 * k + 1] * c4 + U[3 * k + 2] * s4;
        /* the third entry of u Rz(psi_5) Rx(alpha_5) = g Rz(psi_6)^T: sin a5 (u_x sin psi_5 - u_y cos psi_5) = g_z - cos a5 u_z */
        int n5 = lin_trig(-sa5 * u[1], sa5 * u[0], g[2] - ca5 * u[2], 1.0, psi5s), free5 = n5 < 0;
        if (free5) n5 = 1; /* axis 5 parallel to axes 1-3: psi_5 free */
        for (int k5 = 0; k5 < n5; k5++) {
            double psi456[3] = {psi4s[k4], free5 ? 0.0 : psi5s[k5], 0.0};
            double c5 = cos(psi456[1]), s5 = sin(psi456[1]);
            double r0 = u[0] * c5 + u[1] * s5, r1 = -u[0] * s5 + u[1] * c5; /* u Rz(psi_5), then Rx(alpha_5): v */
            double vx = r0, vy = r1 * ca5 + u[2] * sa5;
            int free6 = !free5 && hypot(vx, vy) <= CLOSED_SINGULAR; /* axis 6 parallel to axes 1-3: psi_6 free */
            psi456[2] = free6 ? free_member(p, Tt, psi456, 2) : atan2(g[0] * vy - g[1] * vx, g[0] * vx + g[1] * vy);
            if (free5) psi456[1] = free_member(p, Tt, psi456, 1); /* v, so psi_6, does not move with psi_5 here */
            double x[12];
            int nx = elbows(p, Tt, psi456, x, flags);
            for (int k = 0; k < nx; k++) {
                (*candidates)++;
                double err = closed_polish(&p->k, p->dh, p->scale, Tt, tol, x + 6 * k);
                if (!(err <= tol)) continue;
                for (int i = 0; i < 6; i++) x[6 * k + i] = closed_wrap(x[6 * k + i]);
                closed_keep(qj, ej, found, x + 6 * k, err);
                *flags |= free5 ? 1 : free6 ? 2 : 0;
            }
        }
    }
    closed_sort(qj, ej, *found);
}

int apair_ik_three_parallel(const double *dh, double scale, size_t count, const double *target,
                            ptrdiff_t target_stride, double tol, double *q, double *error, int *found, int *candidates,
                            int *flags)
{
    apair_ik_closed solver;
    if (apair_ik_closed_init(&solver, APAIR_IK_THREE_PARALLEL, dh, scale)) return -1;
    return apair_ik_closed_solve(&solver, count, target, target_stride, tol, q, error, found, candidates, flags);
}
