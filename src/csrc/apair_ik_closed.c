/*
 * The closed-form solvers of six-joint R-chains behind one prepared solver (apair.h: apair_ik_closed,
 * apair_ik_closed_init, apair_ik_closed_solve): a controller reads the design once into storage it
 * owns, then solves pose after pose; nothing is allocated. The families' own steps are in
 * apair_ik_wrist.c and apair_ik_parallel.c. Hand-written C: the C backend of codegen copies it into
 * generated/c.
 */
#include "apair_ik_internal.h"

int apair_ik_closed_init(apair_ik_closed *solver, int family, const double *dh, double scale)
{
    if (!solver) return -1;
    solver->family = 0;
    int rc = family == APAIR_IK_WRIST      ? apair_ik_wrist_prepare(solver->design.d, dh, scale)
             : family == APAIR_IK_PARALLEL ? apair_ik_parallel_prepare(solver->design.d, dh, scale)
                                           : -1;
    if (rc == 0) solver->family = family;
    return rc;
}

int apair_ik_closed_solve(const apair_ik_closed *solver, size_t count, const double *target, ptrdiff_t target_stride,
                          double tol, double *q, double *error, int *found, int *candidates, int *flags)
{
    if (!solver || (solver->family != APAIR_IK_WRIST && solver->family != APAIR_IK_PARALLEL)) return -1;
    for (size_t j = 0; j < count; j++) {
        const double *T = target + (ptrdiff_t)j * target_stride;
        double *qj = q + 6 * CLOSED_MAX * j, *ej = error + CLOSED_MAX * j;
        if (solver->family == APAIR_IK_WRIST)
            apair_ik_wrist_solve1(solver->design.d, T, tol, qj, ej, &found[j], &candidates[j], &flags[j]);
        else
            apair_ik_parallel_solve1(solver->design.d, T, tol, qj, ej, &found[j], &candidates[j], &flags[j]);
    }
    return 0;
}
