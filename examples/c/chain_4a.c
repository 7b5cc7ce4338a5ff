/*
 * chain_4a.c -- the example 4A-chain (examples/4a_chain.toml) with the generated C library:
 * forward kinematics, Jacobian and inverse dynamics at one state, printed one quantity per line.
 *
 * Build from the repository root with every .c file of generated/c (see the README), e.g.
 *   cc -std=c99 -O2 -Igenerated/c examples/c/chain_4a.c generated/c/[a-z]*.c -lm -o chain_4a
 * or with CMake (examples/c/CMakeLists.txt). Run:
 *   ./chain_4a [q1..q4 [qd1..qd4 [qdd1..qdd4]]]      (rad, rad/s, rad/s^2; default zeros)
 *
 * Everything lives on the stack in fixed-size arrays: the pattern for a real-time loop.
 */
#include <stdio.h>
#include <stdlib.h>

#include "apair.h"

#define N 4
#define PI 3.14159265358979323846

/* The chain file's values: per joint (r_b, r_p) [m], DH (a, alpha, c, phi), link
 * (m, com x, y, z, Ixx, Iyy, Izz, Ixy, Ixz, Iyz) and leg mass. */
static const double radii[N][2] = {{0.06, 0.05}, {0.05, 0.05}, {0.05, 0.04}, {0.04, 0.04}};
static const double dh[N][4] = {
    {0.0, PI / 2, 0.20, 0.0}, {0.35, 0.0, 0.0, 0.0}, {0.30, 0.0, 0.0, 0.0}, {0.0, PI / 2, 0.0, PI / 6}};
static const double links[N][10] = {
    {2.0, 0.0, -0.05, 0.0, 0.010, 0.008, 0.010, 0.0, 0.0, 0.0},
    {2.5, -0.17, 0.0, 0.0, 0.004, 0.030, 0.030, 0.0, 0.0, 0.0},
    {1.8, -0.15, 0.0, 0.0, 0.003, 0.016, 0.016, 0.0, 0.0, 0.0},
    {0.8, 0.0, 0.0, 0.03, 0.001, 0.001, 0.0015, 0.0, 0.0, 0.0}};
static const double leg_mass[N] = {0.06, 0.06, 0.05, 0.04};
/* per joint dtheta/dq: 1 where the joint variable is the angle (R-, A-, H-pairs), 0 for a slide (P-pair) */
static const double turning[N] = {1.0, 1.0, 1.0, 1.0};
static const double gravity[3] = {0.0, 0.0, -9.81};

static void print(const char *name, const double *x, int size)
{
    int i;
    printf("%s", name);
    for (i = 0; i < size; ++i) {
        printf(" %.17g", x[i]);
    }
    printf("\n");
}

int main(int argc, char **argv)
{
    double q[N] = {0}, qd[N] = {0}, qdd[N] = {0};
    double law[N][5], legs[N][3];
    double T[16], J[6 * N], tau[N];
    int i;

    if (argc != 1 && argc != 1 + N && argc != 1 + 2 * N && argc != 1 + 3 * N) {
        fprintf(stderr, "usage: %s [q1..q4 [qd1..qd4 [qdd1..qdd4]]]\n", argv[0]);
        return 2;
    }
    for (i = 1; i < argc; ++i) {
        double *x = i <= N ? q : i <= 2 * N ? qd : qdd;
        x[(i - 1) % N] = strtod(argv[i], NULL);
    }
    /* each sinusoidal pair: its amplitude h from the radii, then its law values at its angle,
     * (cos(q/2), sin(q/2), d, d', d''): one sincos per joint, the chain kernels need no other */
    for (i = 0; i < N; ++i) {
        double design[5];
        apair_design_sinusoidal(radii[i], design); /* (L1, L2, a, b, h) */
        apair_law_sinusoidal(&q[i], &design[4], law[i]);
        legs[i][0] = leg_mass[i];
        legs[i][1] = radii[i][0];
        legs[i][2] = radii[i][1];
    }
    apair_fk4(&law[0][0], &dh[0][0], T);
    apair_jacobian4(&law[0][0], &dh[0][0], turning, J);
    apair_inverse_dynamics4(&law[0][0], qd, qdd, &dh[0][0], turning, &links[0][0], &legs[0][0], gravity, tau);
    printf("apair %s (%s)\n", APAIR_VERSION, APAIR_CONTENT_HASH);
    print("T", T, 16);
    print("J", J, 6 * N);
    print("tau", tau, N);
    return 0;
}
