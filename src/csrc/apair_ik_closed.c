/*
 * The closed-form solvers of six-joint chains behind one prepared solver (apair.h: apair_ik_closed,
 * apair_ik_closed_init, apair_ik_closed_solve): a controller reads the design once into storage it
 * owns, then solves pose after pose; nothing is allocated. The families' own steps are in
 * apair_ik_wrist.c, apair_ik_parallel.c (with the arms with A-pairs: a UR arm's at joint 3 or at
 * joints 1 and 5, a spherical wrist's at joint 3 or 1; apair_ik_closed_init_apair, 32 rows a pose) and apair_ik_three_parallel.c. A family at the base
 * end (APAIR_IK_REVERSED) is the reversed chain's (apair.ik.reverse): in standard DH, T^-1 =
 * Tx(-a_6) Rx(-alpha_6) times six DH joints run from the tool, joint k of them with psi' =
 * -psi_{7-k}, c' = -c_{7-k}, a' = -a_{6-k}, alpha' = -alpha_{6-k} (a'_6 = alpha'_6 = 0).
 * Hand-written C: the C backend of codegen copies it into generated/c.
 */
#include "apair_ik_internal.h"

static int form_of(int family) { return family & ~APAIR_IK_REVERSED; }

int apair_ik_closed_init(apair_ik_closed *solver, int family, const double *dh, double scale)
{
    if (!solver) return -1;
    solver->family = 0;
    solver->scale = scale;
    memcpy(solver->dh, dh, sizeof solver->dh);
    double reversed[24];
    const double *use = dh;
    if (family & APAIR_IK_REVERSED) {
        for (int k = 0; k < 6; k++) {
            int j = 5 - k; /* the chain's joint j + 1 */
            reversed[4 * k] = k < 5 ? -dh[4 * (j - 1)] : 0.0;
            reversed[4 * k + 1] = k < 5 ? -dh[4 * (j - 1) + 1] : 0.0;
            reversed[4 * k + 2] = -dh[4 * j + 2];
            reversed[4 * k + 3] = -dh[4 * j + 3];
        }
        closed_dh4(dh[20], cos(dh[21]), sin(dh[21]), 0.0, 0.0, solver->front);
        use = reversed;
    }
    int form = form_of(family);
    int rc = (family & ~(APAIR_IK_THREE_PARALLEL | APAIR_IK_REVERSED)) ? -1
             : form == APAIR_IK_WRIST                                ? apair_ik_wrist_prepare(solver->design.d, use, scale)
             : form == APAIR_IK_PARALLEL                             ? apair_ik_parallel_prepare(solver->design.d, use, scale)
             : form == APAIR_IK_THREE_PARALLEL ? apair_ik_three_parallel_prepare(solver->design.d, use, scale)
                                               : -1;
    if (rc == 0) solver->family = family;
    return rc;
}

int apair_ik_closed_init_apair(apair_ik_closed *solver, const double *dh, const double *amplitude, double scale)
{
    if (!solver || !amplitude) return -1;
    solver->family = 0;
    solver->scale = scale;
    memcpy(solver->dh, dh, sizeof solver->dh);
    int at3 = amplitude[2] != 0.0, elsewhere = 0;
    for (int i = 0; i < 6; i++) elsewhere |= i != 2 && amplitude[i] != 0.0;
    int family = at3 && !elsewhere ? APAIR_IK_PARALLEL_APAIR : !at3 && elsewhere ? APAIR_IK_PARALLEL_SLIDES : 0;
    int rc = -1;
    if (family == APAIR_IK_PARALLEL_APAIR) { /* a UR arm's, else a spherical wrist's with axes 2 and 3 parallel */
        rc = apair_ik_parallel_apair_prepare(solver->design.d, dh, amplitude[2], scale);
        if (rc) {
            family = APAIR_IK_WRIST_APAIR;
            rc = apair_ik_wrist_apair_prepare(solver->design.d, dh, amplitude[2], scale);
        }
    } else if (family == APAIR_IK_PARALLEL_SLIDES) { /* a UR arm's, else a spherical wrist's with one at joint 1 */
        rc = apair_ik_parallel_slides_prepare(solver->design.d, dh, amplitude, scale);
        int joint1 = amplitude[0] != 0.0;
        for (int i = 1; i < 6; i++) joint1 &= amplitude[i] == 0.0;
        if (rc && joint1) {
            family = APAIR_IK_WRIST_SLIDES;
            rc = apair_ik_wrist_slide1_prepare(solver->design.d, dh, amplitude[0], scale);
        }
    }
    if (rc == 0) solver->family = family;
    return rc;
}

/* the family's own solver at one pose T (4 x 4) */
static void solve_form(const apair_ik_closed *solver, const double *T, double tol, double *q, double *error, int *found,
                       int *candidates, int *flags)
{
    int form = form_of(solver->family);
    if (form == APAIR_IK_PARALLEL_APAIR)
        apair_ik_parallel_apair_solve1(solver->design.d, T, tol, q, error, found, candidates, flags);
    else if (form == APAIR_IK_PARALLEL_SLIDES)
        apair_ik_parallel_slides_solve1(solver->design.d, T, tol, q, error, found, candidates, flags);
    else if (form == APAIR_IK_WRIST_APAIR)
        apair_ik_wrist_apair_solve1(solver->design.d, T, tol, q, error, found, candidates, flags);
    else if (form == APAIR_IK_WRIST_SLIDES)
        apair_ik_wrist_slide1_solve1(solver->design.d, T, tol, q, error, found, candidates, flags);
    else if (form == APAIR_IK_WRIST)
        apair_ik_wrist_solve1(solver->design.d, T, tol, q, error, found, candidates, flags);
    else if (form == APAIR_IK_PARALLEL)
        apair_ik_parallel_solve1(solver->design.d, T, tol, q, error, found, candidates, flags);
    else
        apair_ik_three_parallel_solve1(solver->design.d, T, tol, q, error, found, candidates, flags);
}

/* the largest entry of |fk(q) - T| (translations / scale), fk the product of the chain's DH joints */
static double chain_error(const apair_ik_closed *solver, const double *q, const double *T)
{
    const double *dh = solver->dh;
    double F[12], A[12];
    closed_dh4(dh[0], cos(dh[1]), sin(dh[1]), dh[2], q[0] + dh[3], F);
    for (int i = 1; i < 6; i++) {
        closed_dh4(dh[4 * i], cos(dh[4 * i + 1]), sin(dh[4 * i + 1]), dh[4 * i + 2], q[i] + dh[4 * i + 3], A);
        closed_mul34(F, A, F);
    }
    double worst = 0.0;
    for (int k = 0; k < 12; k++) {
        double d = fabs(F[k] - T[k]) / (k % 4 == 3 ? solver->scale : 1.0);
        if (!(d <= worst)) worst = d;
    }
    return isfinite(worst) ? worst : INFINITY;
}

/* A family at the base end: the reversed chain's pose front T^-1 solved to tol (2 + 2 |p| / scale)
 * (its pose error differs from the chain's by the lever |p| / scale of a rotation error), each
 * solution mapped back (theta_{7-k} = -theta'_k) and kept where the chain's own error is <= tol. */
static void solve_reversed(const apair_ik_closed *solver, const double *T, double tol, double *q, double *error,
                           int *found, int *candidates, int *flags)
{
    double inv[12], Tr[16], qr[6 * CLOSED_MAX], er[CLOSED_MAX];
    closed_inv34(T, inv);
    closed_mul34(solver->front, inv, Tr);
    Tr[12] = Tr[13] = Tr[14] = 0.0;
    Tr[15] = 1.0;
    double lever = sqrt(T[3] * T[3] + T[7] * T[7] + T[11] * T[11]) / solver->scale;
    int nr = 0;
    solve_form(solver, Tr, tol * (2 + 2 * lever), qr, er, &nr, candidates, flags);
    *found = 0;
    for (int k = 0; k < nr; k++) {
        double x[6];
        for (int i = 0; i < 6; i++) x[i] = closed_wrap(-qr[6 * k + 5 - i]);
        double err = chain_error(solver, x, T);
        if (!(err <= tol)) continue;
        memcpy(q + 6 * *found, x, sizeof x);
        error[(*found)++] = err;
    }
    closed_sort(q, error, *found);
}

int apair_ik_closed_rows(const apair_ik_closed *solver)
{
    return !solver || !solver->family ? 0
           : solver->family == APAIR_IK_PARALLEL_APAIR || solver->family == APAIR_IK_PARALLEL_SLIDES ||
                   solver->family == APAIR_IK_WRIST_APAIR || solver->family == APAIR_IK_WRIST_SLIDES
               ? CLOSED_APAIR_MAX
               : CLOSED_MAX;
}

int apair_ik_closed_solve(const apair_ik_closed *solver, size_t count, const double *target, ptrdiff_t target_stride,
                          double tol, double *q, double *error, int *found, int *candidates, int *flags)
{
    if (!solver || !solver->family) return -1;
    size_t rows = (size_t)apair_ik_closed_rows(solver); /* per pose */
    for (size_t j = 0; j < count; j++) {
        const double *T = target + (ptrdiff_t)j * target_stride;
        double *qj = q + 6 * rows * j, *ej = error + rows * j;
        if (solver->family & APAIR_IK_REVERSED)
            solve_reversed(solver, T, tol, qj, ej, &found[j], &candidates[j], &flags[j]);
        else
            solve_form(solver, T, tol, qj, ej, &found[j], &candidates[j], &flags[j]);
    }
    return 0;
}
