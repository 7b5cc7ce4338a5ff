"""The closed-form IK's C API as a controller uses it (apair.h: apair_ik_closed_init once, then
apair_ik_closed_solve pose after pose, in storage the program owns; the library allocates nothing,
test_c_hygiene): a program built from the generated sources it needs, with the strict warnings and,
where the compiler links them, ASan and UBSan, gives the Python runtime's solutions on a UR5 (axes
2, 3, 4 parallel), a PUMA 560 (a spherical wrist) and a design with axes 1, 2, 3 parallel and 5, 6
meeting, each also mounted wrist-first (APAIR_IK_REVERSED), UR5s with sinusoidal A-pairs at joint 3 and
at joints 1 and 5 and PUMA 560s with one at joint 3 or 1 (apair_ik_closed_init_apair, 32 rows a pose), and
refuses a chain its family's closed form does not take."""

from __future__ import annotations

import shutil
import subprocess

import numpy as np
import pytest
from test_c_hygiene import CDIR, SANITIZE, STRICT, c_array, sanitizers_link

import apair
from apair.ik.poses import length_scale

PI = np.pi
R = apair.APair.revolute()
ARMS = {  # (family, a, alpha, d)
    "UR5": (
        2,
        [0, -0.425, -0.39225, 0, 0, 0],
        [PI / 2, 0, 0, PI / 2, -PI / 2, 0],
        [0.089159, 0, 0, 0.10915, 0.09465, 0.0823],
    ),
    "PUMA560": (
        1,
        [0, 0.4318, 0.0203, 0, 0, 0],
        [-PI / 2, 0, -PI / 2, PI / 2, -PI / 2, 0],
        [0, 0, 0.15005, 0.4318, 0, 0],
    ),
    "parallel123": (3, [0.3, 0.25, 0.1, 0.05, 0, 0.02], [0, 0, 1.1, -0.7, 0.9, 0.3], [0.2, 0.05, 0.1, 0.15, 0.08, 0.1]),
}


def _upside_down(family: int, a, alpha, d) -> tuple:
    """The arm mounted wrist-first (its reversed chain is the arm, a_6 = 0.05, α_6 = 0.4): the
    family | APAIR_IK_REVERSED (4)."""
    a, alpha, d = (np.asarray(x, float) for x in (a, alpha, d))
    return family | 4, np.append(-a[4::-1], 0.05).tolist(), np.append(-alpha[4::-1], 0.4).tolist(), (-d[::-1]).tolist()


ARMS.update({f"{name}_wrist_first": _upside_down(*ARMS[name]) for name in list(ARMS)})
# the registry's entries for the two kernels the solvers look up (apair_find_kernel): the program
# links these kernels alone, not the whole registry
REGISTRY = """
static void fk6_eval(const double *const *in, double *const *out) { apair_fk6(in[0], in[1], out[0]); }
static void fk6_inv(const double *const *in, double *inv) { apair_fk6_invariants(in[1], inv); }
static void fk6_core(const double *inv, const double *const *in, double *const *out) { apair_fk6_core(inv, in[0], in[1], out[0]); }
static void jac6_eval(const double *const *in, double *const *out) { apair_jacobian6(in[0], in[1], in[2], out[0]); }
static void jac6_inv(const double *const *in, double *inv) { apair_jacobian6_invariants(in[1], in[2], inv); }
static void jac6_core(const double *inv, const double *const *in, double *const *out) {
    apair_jacobian6_core(inv, in[0], in[1], in[2], out[0]);
}
static const apair_kernel KERNELS[2] = {
    {"fk6", 2, 1, NULL, NULL, fk6_eval, NULL, APAIR_FK6_INVARIANTS, fk6_inv, fk6_core},
    {"jacobian6", 3, 1, NULL, NULL, jac6_eval, NULL, APAIR_JACOBIAN6_INVARIANTS, jac6_inv, jac6_core},
};
const apair_kernel *apair_find_kernel(const char *name) {
    return strcmp(name, "fk6") == 0 ? &KERNELS[0] : strcmp(name, "jacobian6") == 0 ? &KERNELS[1] : NULL;
}
"""
SOURCES = [
    "apair_ik_closed.c",
    "apair_ik_wrist.c",
    "apair_ik_parallel.c",
    "apair_ik_three_parallel.c",
    "fk6.c",
    "jacobian6.c",
    "ik_wrist_position6.c",
    "ik_parallel_position6.c",
    "ik_three_parallel6.c",
    "ik_parallel_apair_position6.c",
    "ik_wrist_apair_position6.c",
    "ik_wrist_slide1_position6.c",
]
A = apair.APair(0.06, 0.05)  # at joint 3 of the UR5, or at joints 1 and 5
A_ARMS = {  # (the R arm, its pairs)
    "UR5A": ("UR5", [R, R, A, R, R, R]),
    "UR5A15": ("UR5", [A, R, R, R, A, R]),
    "PUMA560A": ("PUMA560", [R, R, A, R, R, R]),
    "PUMA560A1": ("PUMA560", [A, R, R, R, R, R]),
}


def a_chain(name: str = "UR5A") -> apair.AChain:
    arm, pairs = A_ARMS[name]
    _, a, alpha, d = ARMS[arm]
    return apair.AChain(pairs, a=a, alpha=alpha, offset=d)


def chain(name: str) -> apair.AChain:
    _, a, alpha, d = ARMS[name]
    return apair.AChain([R] * 6, a=a, alpha=alpha, offset=d)


def program(poses: dict[str, np.ndarray], a_poses: dict[str, np.ndarray]) -> str:
    lines = ["#include <stdio.h>", "#include <string.h>", '#include "apair.h"', REGISTRY]
    for name, (_family, a, alpha, d) in ARMS.items():
        dh = np.column_stack([a, alpha, d, np.zeros(6)])
        lines += [c_array(f"dh_{name}", dh), c_array(f"T_{name}", poses[name])]
    for name, (_arm, pairs) in A_ARMS.items():
        amp = [p.amplitude for p in pairs]
        lines += [c_array(f"amp_{name}", np.array(amp)), c_array(f"T_{name}", a_poses[name])]
    lines += [
        "static apair_ik_closed solver; /* about 32 kB: the program's own storage */",
        "static double q[64 * 48], err[64 * 8], qa[64 * 192], erra[64 * 32];",
        "static const double amp_none[6] = {0, 0, 0, 0, 0, 0}, amp_2[6] = {0, 0.0775, 0, 0, 0, 0};",
        "static int found[64], cands[64], flags[64];",
        "int main(void) {",
    ]
    for name, (family, *_rest) in ARMS.items():
        n = len(poses[name])
        lines += [
            f"    if (apair_ik_closed_init(&solver, {family}, dh_{name}, {length_scale(chain(name))!r})) return 1;",
            f"    if (apair_ik_closed_solve(&solver, {n}, T_{name}, 16, 1e-9, q, err, found, cands, flags)) return 2;",
            f"    for (int j = 0; j < {n}; j++) {{",
            f'        printf("{name} %d", found[j]);',
            '        for (int k = 0; k < 6 * found[j]; k++) printf(" %.17g", q[48 * j + k]);',
            '        printf("\\n");',
            "    }",
        ]
    lines += [
        "    /* a PUMA is not a UR: its family's form refuses it */",
        "    if (apair_ik_closed_init(&solver, 2, dh_PUMA560, 0.4) != -1) return 3;",
        "    if (apair_ik_closed_solve(&solver, 1, T_PUMA560, 16, 1e-9, q, err, found, cands, flags) != -1) return 4;",
        "    if (apair_ik_closed_init(&solver, 8, dh_PUMA560, 0.4) != -1) return 5; /* 8 takes an amplitude */",
        "    if (apair_ik_closed_init(&solver, 16, dh_PUMA560, 0.4) != -1) return 6; /* 16 takes amplitudes */",
        "    if (apair_ik_closed_init_apair(&solver, dh_PUMA560, amp_UR5A15, 0.4) != -1) return 7; /* not a UR */",
        "    if (apair_ik_closed_init_apair(&solver, dh_UR5, amp_PUMA560A, 0.4)) return 14; /* the UR form */",
        "    if (solver.family != APAIR_IK_PARALLEL_APAIR) return 15;",
        "    if (apair_ik_closed_init_apair(&solver, dh_PUMA560, amp_PUMA560A, 0.4)) return 16; /* the wrist's */",
        "    if (solver.family != APAIR_IK_WRIST_APAIR) return 17;",
        "    if (apair_ik_closed_init_apair(&solver, dh_PUMA560, amp_PUMA560A1, 0.4)) return 18; /* joint 1 */",
        "    if (solver.family != APAIR_IK_WRIST_SLIDES) return 19;",
        f"    if (apair_ik_closed_init_apair(&solver, dh_UR5, amp_none, {length_scale(a_chain())!r}) != -1) return 10;",
        f"    if (apair_ik_closed_init_apair(&solver, dh_UR5, amp_2, {length_scale(a_chain())!r}) != -1) return 11;",
        "    if (apair_ik_closed_rows(&solver) != 0) return 12; /* not prepared */",
    ]
    for name in A_ARMS:
        n = len(a_poses[name])
        lines += [
            f"    if (apair_ik_closed_init_apair(&solver, dh_{A_ARMS[name][0]}, amp_{name}, "
            f"{length_scale(a_chain(name))!r})) return 8;",
            "    if (apair_ik_closed_rows(&solver) != APAIR_IK_APAIR_MAX || APAIR_IK_APAIR_MAX != 32) return 13;",
            f"    if (apair_ik_closed_solve(&solver, {n}, T_{name}, 16, 1e-9, qa, erra, found, cands, flags)) return 9;",
            f"    for (int j = 0; j < {n}; j++) {{",
            f'        printf("{name} %d", found[j]);',
            '        for (int k = 0; k < 6 * found[j]; k++) printf(" %.17g", qa[192 * j + k]);',
            '        printf("\\n");',
            "    }",
        ]
    lines += [
        "    return 0;",
        "}",
    ]
    return "\n".join(lines) + "\n"


@pytest.mark.skipif(shutil.which("gcc") is None, reason="gcc is required")
def test_a_controller_solves_pose_after_pose_with_one_prepared_solver(tmp_path):
    rng = np.random.default_rng(31)
    poses = {name: chain(name).fk(rng.uniform(-PI, PI, (12, 6))) for name in ARMS}
    a_poses = {}
    for name, (_arm, pairs) in A_ARMS.items():
        qa = rng.uniform(-PI, PI, (12, 6))
        for i, p in enumerate(pairs):
            if p.kind != "revolute":
                qa[:, i] = rng.uniform(-2 * PI, 2 * PI, 12)
        a_poses[name] = a_chain(name).fk(qa)
    src = tmp_path / "closed.c"
    src.write_text(program(poses, a_poses))
    flags = ["-std=c99", *STRICT, "-O1", f"-I{CDIR}"] + (SANITIZE if sanitizers_link("gcc", tmp_path) else [])
    exe = tmp_path / "closed"
    subprocess.run(["gcc", *flags, str(src), *(str(CDIR / s) for s in SOURCES), "-o", str(exe), "-lm"], check=True)
    out = subprocess.run([str(exe)], check=True, capture_output=True, text=True).stdout.split("\n")
    rows = [line.split() for line in out if line]
    assert len(rows) == sum(len(p) for p in poses.values()) + sum(len(p) for p in a_poses.values())
    for name in ARMS:
        mine = [r for r in rows if r[0] == name]
        for T, row in zip(poses[name], mine):
            q = np.array(row[2:], float).reshape(int(row[1]), 6)
            ours = chain(name).ik(T)  # the runtime's numbers (its own build's rounding: 1e-12)
            assert q.shape == ours.shape and len(q) >= 1 and np.allclose(q, ours, rtol=0, atol=1e-12), name
    for name in A_ARMS:
        for T, row in zip(a_poses[name], [r for r in rows if r[0] == name]):
            q = np.array(row[2:], float).reshape(int(row[1]), 6)
            ours = a_chain(name).ik(T)
            assert q.shape == ours.shape and len(q) >= 1 and np.allclose(q, ours, rtol=0, atol=1e-12), name
