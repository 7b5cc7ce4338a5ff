"""Code for a user's own chain (`apair codegen`, apair.specialise): the generated C builds strictly
(C99 and C++, -Werror, under ASan/UBSan), its self-test passes, and C, NumPy and the specialised
chain agree with the generic kernels on random states of random and special chains."""

from __future__ import annotations

import importlib.util
import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import apair
from apair import specialise

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "dynamics"))
from test_dynamics import random_chain, random_link, special_chain

ROOT = Path(__file__).resolve().parents[2]
STRICT = ["-Wall", "-Wextra", "-Werror", "-pedantic"]
SANITIZE = ["-fsanitize=address,undefined", "-fno-sanitize-recover=all", "-fno-omit-frame-pointer"]
gcc = pytest.mark.skipif(shutil.which("gcc") is None, reason="gcc is required")


def ranged_chain(rng) -> apair.AChain:
    """Two general pairs with a < b (a limited range, d → 0 at its ends) and an R-pair, twists 90°."""
    pairs = []
    for _ in range(2):
        r_b, r_p = rng.uniform(0.05, 0.2, 2)
        b = r_b * r_p
        pairs.append(apair.APair(r_b, r_p, leg_length=np.sqrt(0.5 * b + r_b**2 + r_p**2 / 4), leg_mass=0.05))
    pairs.append(apair.APair.revolute())
    return apair.AChain(
        pairs,
        [0.0, 0.2, 0.1],
        [np.pi / 2, 0.0, -np.pi / 2],
        [0.1, 0.0, 0.0],
        [0.0, np.pi / 2, 0.0],
        links=[random_link(rng) for _ in range(3)],
    )


def chains():
    rng = np.random.default_rng(16)
    return {
        "r6": random_chain(rng, 6, kinds=("revolute",)),
        "mixed3": random_chain(rng, 3, legs=True),
        "special4": special_chain(rng, 4),
        "ranged3": ranged_chain(rng),
        "one": random_chain(rng, 1, kinds=("sinusoidal",), legs=True),
        "example": apair.load(ROOT / "examples" / "4a_chain.toml"),
    }


@pytest.fixture(scope="module")
def generated(tmp_path_factory):
    """{name: (chain, folder)} with each chain's code written by specialise.write_code."""
    out = {}
    for name, chain in chains().items():
        folder = tmp_path_factory.mktemp(name)
        specialise.write_code(chain, folder, name, f"{name}.toml")
        out[name] = chain, folder
    return out


def run(cmd, **kw):
    res = subprocess.run(cmd, capture_output=True, text=True, **kw)
    assert res.returncode == 0, f"{' '.join(map(str, cmd))} failed:\n{res.stdout}\n{res.stderr}"
    return res


def states(chain, count, rng):
    """Random states inside the limits, with joints at 0 and (where allowed) ±π among them."""
    lim = chain.limits
    q = rng.uniform(lim[:, 0], lim[:, 1], (count, chain.n))
    q[0] = np.clip(0.0, lim[:, 0], lim[:, 1])
    q[1] = np.where((lim[:, 0] <= -np.pi) & (lim[:, 1] >= np.pi), np.pi, q[1])
    ranged = np.array([p.theta_limit is not None for p in chain.pairs])
    mid = lim.mean(axis=1)
    q = np.where(ranged, mid + 0.999 * (q - mid), q)  # velocity-level kernels need d' finite
    return q, rng.normal(size=(count, chain.n)), rng.normal(size=(count, chain.n)), rng.normal(size=(count, chain.n))


def generic(chain, kernel, q, qd, qdd, tau):
    args = {"q": q, "qd": qd, "qdd": qdd, "tau": tau}
    method = {"coriolis": "coriolis_matrix"}.get(kernel, kernel)
    names = {
        "fk": "q",
        "fk_study": "q",
        "jacobian": "q",
        "mass_matrix": "q",
        "gravity_torques": "q",
        "coriolis": "q qd",
        "bias": "q qd",
        "energy": "q qd",
        "inverse_dynamics": "q qd qdd",
        "forward_dynamics": "q qd tau",
    }[kernel].split()
    return getattr(chain, method)(*(args[n] for n in names)), [args[n] for n in names]


def close(got, want):
    scale = np.maximum(1.0, np.max(np.abs(want), axis=tuple(range(1, want.ndim)), keepdims=True))
    assert np.all(np.abs(got - want) <= 1e-12 * scale), np.max(np.abs(got - want) / scale)


@pytest.mark.slow
@gcc
@pytest.mark.parametrize("lang", ["c99", "c++17"])
def test_generated_c_builds_strictly_and_passes_its_selftest(generated, lang):
    for name, (_chain, folder) in generated.items():
        exe = folder / f"selftest_{lang}"
        x = ["-x", "c++"] if lang.startswith("c++") else []
        cc = "g++" if x else "gcc"
        if shutil.which(cc) is None:
            pytest.skip(f"{cc} is not installed")
        run(
            [
                cc,
                *x,
                f"-std={lang}",
                *STRICT,
                "-O2",
                str(folder / f"{name}_selftest.c"),
                str(folder / f"{name}.c"),
                "-o",
                str(exe),
                "-lm",
            ]
        )
        assert "checks passed" in run([str(exe)]).stdout


@gcc
def test_generated_c_is_clean_under_sanitizers(generated, tmp_path):
    probe = tmp_path / "probe.c"
    probe.write_text("int main(void) { return 0; }\n")
    if subprocess.run(["gcc", *SANITIZE, str(probe), "-o", str(tmp_path / "probe")], capture_output=True).returncode:
        pytest.skip("gcc has no sanitizer runtime here")
    for name in ("mixed3", "ranged3"):
        chain, folder = generated[name]
        exe = tmp_path / name
        run(
            [
                "gcc",
                "-std=c99",
                *STRICT,
                "-O1",
                *SANITIZE,
                str(folder / f"{name}_selftest.c"),
                str(folder / f"{name}.c"),
                "-o",
                str(exe),
                "-lm",
            ]
        )
        res = run(
            [str(exe)], env={"ASAN_OPTIONS": "detect_leaks=1:abort_on_error=1", "UBSAN_OPTIONS": "halt_on_error=1"}
        )
        assert res.stderr == ""


def test_numpy_module_equals_the_generic_kernels(generated):
    rng = np.random.default_rng(3)
    for name, (chain, folder) in generated.items():
        spec = importlib.util.spec_from_file_location(f"spec_{name}", folder / f"{name}.py")
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        assert module.N == chain.n
        q, qd, qdd, tau = states(chain, 25, rng)
        for kernel in specialise.check_kernels(None):
            want, args = generic(chain, kernel, q, qd, qdd, tau)
            got = getattr(module, kernel)(*args)
            if kernel == "fk_study":
                got = got / np.linalg.norm(got[:, :4], axis=1, keepdims=True)
            close(got.reshape(want.shape), want)


@pytest.mark.slow
def test_output_is_deterministic_and_named_by_content(generated, tmp_path):
    chain, folder = generated["special4"]
    again = specialise.render(chain, "special4", "special4.toml")
    for rel, text in again.items():
        if rel == "manifest.json":
            # on disk, the writer adds the SHA-256 of every file it wrote (codegen.output)
            written = json.loads((folder / rel).read_text())
            assert written.pop("files").keys() == set(again) - {"manifest.json"}
            assert written == json.loads(text)
        else:
            assert (folder / rel).read_text() == text, rel
    header = (folder / "special4.h").read_text()
    assert "#define special4_N 4" in header
    assert f'special4_CONTENT_HASH "{specialise.content_hash(chain, specialise.check_kernels(None))}"' in header
    # another design, another hash; a subset of kernels, fewer functions
    other = specialise.render(chain, "special4", "special4.toml", kernels=["fk", "jacobian"])
    assert "special4_mass_matrix" not in other["special4.h"] and "special4_jacobian_batch" in other["special4.h"]
    assert other["manifest.json"] != again["manifest.json"]


@pytest.mark.slow
def test_special_constants_fold_exactly():
    """Twists of 90° give exact zeros, so the specialised kernels have fewer operations than the
    same chain with a twist one degree off; an R-chain has no law terms (no d)."""
    rng = np.random.default_rng(5)
    base = special_chain(rng, 3)
    off = apair.AChain(
        base.pairs,
        base.a,
        base.alpha + np.radians(1.0),
        base.offset,
        base.theta_offset,
        links=base.links,
        gravity=base.gravity,
    )
    ops = lambda ch: {k.name: k.ops for k in specialise.lowered(ch, ("fk", "mass_matrix"))[0]}
    assert all(a < b for a, b in zip(ops(base).values(), ops(off).values()))


@pytest.mark.slow
def test_cli_codegen_writes_refuses_and_explains(tmp_path, capsys):
    from apair.cli import main

    out = tmp_path / "arm"
    assert (
        main(["codegen", str(ROOT / "examples" / "4a_chain.toml"), "--out", str(out), "--kernels", "fk,jacobian"]) == 0
    )
    assert {p.name for p in out.iterdir()} == {
        "chain_4a_chain.h",
        "chain_4a_chain.c",
        "chain_4a_chain.py",
        "chain_4a_chain_selftest.c",
        "chain_4a_chain.pc.in",
        "CMakeLists.txt",
        "manifest.json",
    }
    # again into the same folder: allowed (it wrote it); into a folder of someone else's: refused
    assert main(["codegen", str(ROOT / "examples" / "4a_chain.toml"), "--out", str(out), "--kernels", "fk"]) == 0
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "notes.txt").write_text("keep")
    capsys.readouterr()
    assert main(["codegen", str(ROOT / "examples" / "4a_chain.toml"), "--out", str(mine)]) == 2
    assert "not empty" in capsys.readouterr().err and (mine / "notes.txt").read_text() == "keep"
    for bad, what in (
        (["--prefix", "1arm"], "prefix"),
        (["--prefix", "int"], "prefix"),
        (["--kernels", "fk,warp"], "kernels"),
    ):
        assert main(["codegen", str(ROOT / "examples" / "4a_chain.toml"), "--out", str(tmp_path / "x"), *bad]) == 2
        assert f"error: {what}" in capsys.readouterr().err


# ------------------------------------------------------------------------ AChain.specialise, fast path
@pytest.fixture
def cache() -> Path:
    """The compiled chains' cache of this test session (conftest points APAIR_CACHE at it)."""
    import os

    return Path(os.environ["APAIR_CACHE"])


METHODS = [
    "fk",
    "fk_study",
    "jacobian",
    "mass_matrix",
    "coriolis_matrix",
    "gravity_torques",
    "bias",
    "inverse_dynamics",
    "forward_dynamics",
    "energy",
]


def method_args(method, q, qd, qdd, tau):
    return {
        "coriolis_matrix": (q, qd),
        "bias": (q, qd),
        "energy": (q, qd),
        "inverse_dynamics": (q, qd, qdd),
        "forward_dynamics": (q, qd, tau),
    }.get(method, (q,))


@pytest.mark.slow
@gcc
def test_specialised_chain_equals_the_generic_one(cache):
    """Single calls, batches, lists and broadcast inputs of the compiled specialised chains against
    the generic kernels (NumPy backend: independent of both native paths)."""
    rng = np.random.default_rng(11)
    for _name, chain in chains().items():
        fast = chain.specialise()
        assert fast.specialised and isinstance(fast, apair.AChain) and fast.n == chain.n
        q, qd, qdd, tau = states(chain, 40, rng)
        apair.set_backend("numpy")
        try:
            want = {m: getattr(chain, m)(*method_args(m, q, qd, qdd, tau)) for m in METHODS}
        finally:
            apair.set_backend(None)
        for m in METHODS:
            got = getattr(fast, m)(*method_args(m, q, qd, qdd, tau))
            close(got, want[m])
            single = getattr(fast, m)(*method_args(m, q[3], qd[3], qdd[3], tau[3]))
            close(single[None], want[m][3:4])
            listed = getattr(fast, m)(*(x.tolist() for x in method_args(m, q[3], qd[3], qdd[3], tau[3])))
            close(listed[None], want[m][3:4])
            generic = getattr(chain, m)(*method_args(m, q, qd, qdd, tau))  # the generic fast path
            close(generic, want[m])
        # one q for a batch of velocities broadcasts
        close(fast.bias(q[0], qd[:5]), chain.bias(np.broadcast_to(q[0], (5, chain.n)), qd[:5]))


@pytest.mark.slow
@gcc
def test_specialised_builds_are_cached_by_content(cache):
    chain = chains()["mixed3"]
    first = chain.specialise()
    builds = sorted(p.name for p in (cache / "specialised").iterdir())
    again = chain.specialise()
    assert sorted(p.name for p in (cache / "specialised").iterdir()) == builds  # found again, not rebuilt
    assert again.content_hash == first.content_hash
    other = apair.AChain(
        chain.pairs,
        chain.a + 0.01,
        chain.alpha,
        chain.offset,
        chain.theta_offset,
        links=chain.links,
        gravity=chain.gravity,
    ).specialise()
    assert other.content_hash != first.content_hash and (cache / "specialised" / other.content_hash).is_dir()
    subset = chain.specialise(kernels=["fk"])
    q = np.array([0.1, 0.2, 0.3])
    close(subset.mass_matrix(q)[None], chain.mass_matrix(q)[None])  # the others stay generic
    import pickle

    back = pickle.loads(pickle.dumps(first))
    assert back.specialised and np.array_equal(back.fk(q), first.fk(q))


def test_missing_compiler_falls_back_once(cache, monkeypatch):
    monkeypatch.setenv("APAIR_CACHE", str(cache / "empty"))
    monkeypatch.setattr(specialise, "_compiler", lambda: None)
    monkeypatch.setattr(specialise, "_warned", set())
    chain = chains()["one"]
    with pytest.warns(RuntimeWarning, match="no C compiler"):
        fast = chain.specialise()
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        again = chain.specialise()
    assert not fast.specialised and not again.specialised
    q = np.array([0.4])
    assert np.array_equal(fast.fk(q), chain.fk(q))


@pytest.mark.slow
@pytest.mark.parametrize("specialised", [False, True])
def test_bad_inputs_are_refused_on_every_path(cache, specialised):
    """Whatever the fast path is handed, a bad input ends in the ValueError that names it."""
    chain = ranged_chain(np.random.default_rng(2))
    if specialised:
        if shutil.which("gcc") is None:
            pytest.skip("gcc is required")
        chain = chain.specialise()
    n = chain.n
    ok = np.zeros(n)
    lim = chain.pairs[0].theta_limit
    cases = [
        ("q", lambda: chain.fk(np.array([np.nan] + [0.0] * (n - 1))), "NaN"),
        ("q", lambda: chain.mass_matrix(np.full(n, np.inf)), "NaN or infinite"),
        ("q", lambda: chain.jacobian(np.zeros(n + 1)), "shape"),
        ("q", lambda: chain.fk(np.zeros(n, dtype=complex)), "real numbers"),
        ("qd", lambda: chain.bias(ok, np.array([np.nan] * n)), "NaN"),
        ("qdd", lambda: chain.inverse_dynamics(ok, ok, np.zeros((2, n + 1))), "shape"),
        ("qd", lambda: chain.energy(np.zeros((3, n)), np.zeros((2, n))), "batch shape"),
        ("q[..., 0] (joint 1)", lambda: chain.fk(np.array([lim + 0.1] + [0.0] * (n - 1))), "outside this pair's range"),
        ("q", lambda: chain.mass_matrix(np.array([lim] + [0.0] * (n - 1))), "limit"),
    ]
    for name, fn, what in cases:
        with pytest.raises(ValueError, match=rf"^{re.escape(name)}: .*{what}"):
            fn()
    # what the fast path takes as it is and what it hands over give the same numbers
    q = np.array([0.3, -0.2, 1.0])
    for variant in (q.astype(np.float32), q.astype(">f8"), np.stack([q, q], axis=1)[:, 0], q.tolist(), q.astype(int)):
        np.testing.assert_array_equal(chain.fk(variant), chain.fk(np.asarray(variant, dtype=np.float64)))
    # rounding past the range end is put on it (position level), the end itself refused for dynamics
    np.testing.assert_allclose(chain.fk(np.array([np.nextafter(lim, 4.0), 0, 0])), chain.fk(np.array([lim, 0, 0])))


def test_forward_dynamics_of_a_massless_chain_is_refused(cache):
    chain = apair.AChain([apair.APair.revolute()] * 2, [0.3, 0.2], [0.0, 0.0])
    with pytest.raises(ValueError, match="^links: the mass matrix is not positive definite"):
        chain.forward_dynamics(np.zeros(2), np.zeros(2), np.zeros(2))


def test_numpy_backend_turns_the_fast_path_off():
    chain = chains()["mixed3"]
    q = np.array([0.1, 0.2, 0.3])
    c = chain.fk(q)
    apair.set_backend("numpy")
    try:
        assert chain._fast.call(0, q) is None
        assert apair.backend() == "numpy" and chain._fast.call(0, q) is None
        np.testing.assert_allclose(chain.fk(q), c, atol=1e-15)
    finally:
        apair.set_backend(None)
    chain.fk(q)
    assert chain._fast.call(0, q) is not None


@gcc
def test_committed_example_code_builds_and_passes_its_selftest(tmp_path):
    """examples/codegen/chain4a (regenerated by make, compared by make check) as a user builds it."""
    folder = ROOT / "examples" / "codegen" / "chain4a"
    exe = tmp_path / "selftest"
    run(
        [
            "cc",
            "-std=c99",
            *STRICT,
            str(folder / "chain4a_selftest.c"),
            str(folder / "chain4a.c"),
            "-o",
            str(exe),
            "-lm",
        ]
    )
    assert "checks passed" in run([str(exe)]).stdout
