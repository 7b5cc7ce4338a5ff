/*
 * The input file of bench/native.py, read by every timing program (C and C++): count and n, then
 * q, qd, qdd, tau (count x n each), dh (n x 4), links (n x 10), legs (n x 3), gravity (3) and each
 * joint's law parameter (n), all doubles. Also the clock.
 */
#ifndef BENCH_INPUTS_H
#define BENCH_INPUTS_H

#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#define MAX_N 7 /* the generated kernels' largest chain */
static double *Q, *QD, *QDD, *TAU, DH[4 * MAX_N], TURN[MAX_N], LINKS[10 * MAX_N], LEGS[3 * MAX_N], GRAV[3], LAWP[MAX_N];
static long COUNT;
static int N;

static int read_inputs(const char *path)
{
    FILE *f = fopen(path, "rb");
    double head[2];
    long k;
    if (!f || fread(head, sizeof(double), 2, f) != 2) return 1;
    COUNT = (long)head[0];
    N = (int)head[1];
    if (N < 1 || N > MAX_N) return 1;
    Q = (double *)malloc(sizeof(double) * COUNT * N);
    QD = (double *)malloc(sizeof(double) * COUNT * N);
    QDD = (double *)malloc(sizeof(double) * COUNT * N);
    TAU = (double *)malloc(sizeof(double) * COUNT * N);
    k = COUNT * N;
    if (fread(Q, sizeof(double), k, f) != (size_t)k || fread(QD, sizeof(double), k, f) != (size_t)k
        || fread(QDD, sizeof(double), k, f) != (size_t)k || fread(TAU, sizeof(double), k, f) != (size_t)k
        || fread(DH, sizeof(double), 4 * N, f) != (size_t)(4 * N) || fread(TURN, sizeof(double), N, f) != (size_t)N
        || fread(LINKS, sizeof(double), 10 * N, f) != (size_t)(10 * N)
        || fread(LEGS, sizeof(double), 3 * N, f) != (size_t)(3 * N) || fread(GRAV, sizeof(double), 3, f) != 3
        || fread(LAWP, sizeof(double), N, f) != (size_t)N) return 1;
    fclose(f);
    return 0;
}

static double now_ns(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec * 1e9 + t.tv_nsec;
}

#endif
