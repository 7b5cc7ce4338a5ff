"""Base and tool frames in the code generated for a user's chain (issue 38; `apair codegen`,
`AChain.specialise()`): the generated C (through ctypes), its NumPy module and the specialised
chain equal the runtime's chain with frames; the frame-0 functions (name_fk_dh, ...) equal the
frameless chain; the tool's kinematics are checked against an independent composition in numpy,
finite differences of the generated fk and the Study point of its pose; the dynamics against a
frameless chain with gravity rotated into frame 0 by hand. A chain without frames gets the code it
got before frames existed."""

from __future__ import annotations

import ctypes
import hashlib
import importlib.util
import json
import shutil
import subprocess
import sys
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

import apair
from apair import specialise
from apair.frames import rpy_matrix
from apair.study import to_matrix

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "frames"))
from test_frames_kinematics import random_design, random_frame

ROOT = Path(__file__).resolve().parents[2]
STRICT = ["-Wall", "-Wextra", "-Werror", "-pedantic"]
gcc = pytest.mark.skipif(shutil.which("gcc") is None, reason="gcc is required")
DYNAMICS = ("mass_matrix", "gravity_torques", "inverse_dynamics")
SOME = ("fk", "fk_study", "jacobian", *DYNAMICS)  # the 6-joint A-chain's kernels (its code takes long)
METHOD = {"coriolis": "coriolis_matrix"}
SHAPE = {
    "fk": lambda n: (4, 4),
    "fk_study": lambda n: (8,),
    "jacobian": lambda n: (6, n),
    "mass_matrix": lambda n: (n, n),
    "coriolis": lambda n: (n, n),
    "gravity_torques": lambda n: (n,),
    "bias": lambda n: (n,),
    "inverse_dynamics": lambda n: (n,),
    "forward_dynamics": lambda n: (n,),
    "energy": lambda n: (2,),
}
INPUTS = {"coriolis": 2, "bias": 2, "energy": 2, "inverse_dynamics": 3, "forward_dynamics": 3}


def framed_cases() -> dict[str, tuple[apair.AChain, apair.AChain, tuple[str, ...] | None]]:
    """{name: (chain with frames, the frameless chain with gravity R_bᵀ g, kernels)}: A-pairs
    and R-pairs, n = 2 and 6, base and tool with translations; a tool that only rotates (the
    Jacobian has no ω × r) and no base."""
    rng = np.random.default_rng(38)
    out = {}
    for name, n, kinds, base, tool, kernels in (
        ("a2", 2, ("sinusoidal", "general"), True, "full", None),
        ("r6", 6, ("revolute",), True, "full", None),
        ("a6", 6, ("sinusoidal", "general", "revolute"), True, "full", SOME),
        ("r2", 2, ("revolute",), False, "rotation", None),
    ):
        d = random_design(rng, n, kinds)
        B = random_frame(rng) if base else None
        T = random_frame(rng, 0.2)
        if tool == "rotation":
            T[:3, 3] = 0.0
        framed = apair.AChain(**d, base=B, tool=T)
        Rb = np.eye(3) if B is None else B[:3, :3]
        plain = apair.AChain(**dict(d, gravity=Rb.T @ d["gravity"]))
        out[name] = framed, plain, kernels
    return out


def run(cmd, **kw):
    res = subprocess.run(cmd, capture_output=True, text=True, **kw)
    assert res.returncode == 0, f"{' '.join(map(str, cmd))} failed:\n{res.stdout}\n{res.stderr}"
    return res


def close(got, want, tol=1e-12):
    """got = want to tol relative to the largest entry of each item (at least 1)."""
    got, want = np.asarray(got), np.asarray(want)
    assert got.shape == want.shape, (got.shape, want.shape)
    axes = tuple(range(1, want.ndim))
    scale = np.maximum(1.0, np.max(np.abs(want), axis=axes, keepdims=True))
    assert np.all(np.abs(got - want) <= tol * scale), np.max(np.abs(got - want) / scale)


def states(chain, count, rng):
    lim = chain.limits
    mid, half = lim.mean(axis=1), (lim[:, 1] - lim[:, 0]) / 2
    q = mid + 0.95 * half * rng.uniform(-1, 1, (count, chain.n))
    return q, *(rng.normal(size=(3, count, chain.n)))


class Library:
    """The generated name.c built into a shared library, its batch functions called by ctypes."""

    def __init__(self, folder: Path, name: str, n: int):
        so = folder / f"lib{name}.so"
        run(["gcc", "-std=c99", *STRICT, "-O2", "-fPIC", "-shared", str(folder / f"{name}.c"), "-o", str(so), "-lm"])
        self.lib, self.name, self.n = ctypes.CDLL(str(so)), name, n

    def __call__(self, kernel: str, *inputs: np.ndarray) -> np.ndarray:
        shape = SHAPE[kernel.removesuffix("_dh")](self.n)
        ins = [np.ascontiguousarray(x, dtype=np.float64) for x in inputs]
        out = np.full((len(ins[0]), *shape), np.nan)
        ptr = lambda a: a.ctypes.data_as(ctypes.POINTER(ctypes.c_double))
        fn = getattr(self.lib, f"{self.name}_{kernel}_batch")
        fn.restype = None
        fn(ctypes.c_size_t(len(ins[0])), *(ptr(x) for x in ins), ptr(out))
        return out


@pytest.fixture(scope="module")
def generated(tmp_path_factory):
    """{name: (framed, plain, kernels, folder)}, each framed chain's code written by write_code."""
    out = {}
    for name, (framed, plain, kernels) in framed_cases().items():
        folder = tmp_path_factory.mktemp(name)
        specialise.write_code(framed, folder, name, f"{name}.toml", kernels=kernels)
        out[name] = framed, plain, kernels, folder
    return out


def names(kernels):
    return specialise.check_kernels(kernels)


def args_of(kernel, q, qd, qdd, tau):
    return (q, qd, qdd if kernel != "forward_dynamics" else tau)[: INPUTS.get(kernel, 1)]


@pytest.mark.slow
@gcc
def test_generated_c_equals_the_chain_with_frames(generated):
    """Every generated function (ctypes) against the runtime's chain with frames, the frame-0
    functions against the frameless chain, to 1e-12; fk against B · fk_plain · T composed here,
    fk_study against fk's pose, the Jacobian against finite differences of the generated fk."""
    rng = np.random.default_rng(1)
    for name, (framed, plain, kernels, folder) in generated.items():
        c = Library(folder, name, framed.n)
        q, qd, qdd, tau = states(framed, 30, rng)
        for k in names(kernels):
            args = args_of(k, q, qd, qdd, tau)
            want = getattr(framed, METHOD.get(k, k))(*args)
            got = c(k, *args)
            close(got, want)
            if k in DYNAMICS:  # gravity R_bᵀ g in frame 0, rotated by hand
                close(got, getattr(plain, k)(*args))
        for k in ("fk", "fk_study", "jacobian"):
            close(c(f"{k}_dh", q), getattr(plain, k)(q))
        T = c("fk", q)
        close(T, framed.base @ plain.fk(q) @ framed.tool)
        study = c("fk_study", q)
        close(np.linalg.norm(study[:, :4], axis=1), np.ones(len(q)))
        close(to_matrix(study), T, 1e-11)
        # the Jacobian: central differences of the generated fk (position; ω from Ṙ Rᵀ)
        J, h = c("jacobian", q[:5]), 1e-6
        for j in range(framed.n):
            dq = np.zeros(framed.n)
            dq[j] = h
            Tp, Tm = c("fk", q[:5] + dq), c("fk", q[:5] - dq)
            v = (Tp[:, :3, 3] - Tm[:, :3, 3]) / (2 * h)
            W = (Tp[:, :3, :3] - Tm[:, :3, :3]) / (2 * h) @ np.swapaxes(T[:5, :3, :3], 1, 2)
            w = np.stack([W[:, 2, 1], W[:, 0, 2], W[:, 1, 0]], axis=1)
            np.testing.assert_allclose(J[:, :3, j], v, atol=1e-7)
            np.testing.assert_allclose(J[:, 3:, j], w, atol=1e-7)


@pytest.mark.slow
@gcc
def test_selftest_with_frames_passes_and_checks_them(generated, tmp_path):
    """The self-test builds strictly (C99, C++17), passes, and checks the tool's kernels and the
    frame-0 ones; a self-test whose base is wrong fails."""
    for name, (_framed, _plain, _kernels, folder) in generated.items():
        if name == "a6":
            continue  # the same code paths as a2 and r6
        source = (folder / f"{name}_selftest.c").read_text()
        assert f"{name}_fk_dh_batch(" in source and f"{name}_jacobian_batch(" in source
        for lang, cc, x in (("c99", "gcc", []), ("c++17", "g++", ["-x", "c++"])):
            if shutil.which(cc) is None:
                continue
            exe = tmp_path / f"{name}_{lang}"
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
            out = run([str(exe)]).stdout
            assert "checks passed (13 kernels" in out, out
    # the same self-test against code built with another base: it fails
    _framed, _plain, _kernels, folder = generated["a2"]
    bad = tmp_path / "bad"
    shutil.copytree(folder, bad)
    header = (bad / "a2.h").read_text()
    start = header.index("#define a2_BASE {")
    first = header[start:].split("\n")[1].split(",")[0]
    (bad / "a2.h").write_text(header[:start] + header[start:].replace(first, f"{first} + 1e-6", 1))
    exe = tmp_path / "bad_selftest"
    run(["gcc", "-std=c99", "-O2", str(bad / "a2_selftest.c"), str(bad / "a2.c"), "-o", str(exe), "-lm"])
    res = subprocess.run([str(exe)], capture_output=True, text=True)
    assert res.returncode == 1 and "a2_fk (single)" in res.stdout


@pytest.mark.slow
def test_numpy_module_with_frames(generated):
    rng = np.random.default_rng(2)
    for name, (framed, plain, kernels, folder) in generated.items():
        spec = importlib.util.spec_from_file_location(f"frames_{name}", folder / f"{name}.py")
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        np.testing.assert_array_equal(module.BASE, framed.base)
        np.testing.assert_array_equal(module.TOOL, framed.tool)
        q, qd, qdd, tau = states(framed, 20, rng)
        for k in names(kernels):
            args = args_of(k, q, qd, qdd, tau)
            got, want = getattr(module, k)(*args), getattr(framed, METHOD.get(k, k))(*args)
            if k == "fk_study":
                got = got / np.linalg.norm(got[:, :4], axis=1, keepdims=True)
            close(got, want)
        close(module.fk_dh(q), plain.fk(q))
        close(module.jacobian_dh(q[0]), plain.jacobian(q[0]))  # one item, no batch axis


@pytest.mark.slow
@gcc
def test_specialised_chain_with_frames_equals_the_generic_one():
    """chain.specialise() of chains with frames: single calls and batches against the generic
    kernels (NumPy backend), the frames kept (base, tool, repr)."""
    rng = np.random.default_rng(3)
    for _name, (framed, _plain, kernels) in framed_cases().items():
        fast = framed.specialise(kernels)
        assert fast.specialised and np.array_equal(fast.base, framed.base) and np.array_equal(fast.tool, framed.tool)
        q, qd, qdd, tau = states(framed, 12, rng)
        methods = [METHOD.get(k, k) for k in names(kernels)]
        apair.set_backend("numpy")
        try:
            want = {m: getattr(framed, m)(*args_of(k, q, qd, qdd, tau)) for k, m in zip(names(kernels), methods)}
        finally:
            apair.set_backend(None)
        for k, m in zip(names(kernels), methods):
            args = args_of(k, q, qd, qdd, tau)
            close(getattr(fast, m)(*args), want[m])
            close(getattr(fast, m)(*(a[4] for a in args))[None], want[m][4:5])
        if kernels is not None:  # the others stay generic and framed
            close(fast.energy(q, qd), framed.energy(q, qd))
        if framed.n == 2:  # ik of the tool's world pose through the specialised frame-0 kernels
            T = fast.fk(q[0])
            sols = fast.ik(T)
            assert len(sols) >= 1 and all(np.abs(fast.fk(s) - T).max() < 1e-8 for s in sols)


def test_content_hash_covers_the_frames():
    rng = np.random.default_rng(4)
    d = random_design(rng, 2, ("revolute",))
    B, T = random_frame(rng), random_frame(rng, 0.2)
    h = lambda **kw: specialise.content_hash(apair.AChain(**d, **kw), ("fk", "jacobian"))
    plain, framed = h(), h(base=B, tool=T)
    other_base, other_tool = B.copy(), T.copy()
    other_base[2, 3] += 1e-9
    other_tool[:3, :3] = T[:3, :3] @ rpy_matrix([1e-6, 0.0, 0.0])
    hashes = [plain, framed, h(base=other_base, tool=T), h(base=B, tool=other_tool), h(base=B), h(tool=T), h(base=T)]
    assert len(set(hashes)) == len(hashes)
    assert h(base=np.eye(4), tool=np.eye(4)) == plain  # identity frames are no frames
    assert h(base=B, tool=T) == framed


def test_frameless_hash_and_design_are_as_before(monkeypatch):
    """Without frames the hashed text is the design's alone (the hash of before frames existed),
    with the world's gravity; with a base, the design's gravity is R_bᵀ g."""
    monkeypatch.setattr(specialise, "toolkit_digest", lambda: "fixed")
    rng = np.random.default_rng(5)
    d = random_design(rng, 3)
    chain = apair.AChain(**d)
    design = specialise.design_of(chain)
    want = hashlib.sha256(design.canonical().encode())
    want.update(("fk,mass_matrix" + "\0" + "fixed").encode())
    assert specialise.content_hash(chain, ["mass_matrix", "fk"]) == want.hexdigest()[:16]
    assert design.gravity == tuple(d["gravity"])
    B = random_frame(rng)
    framed = specialise.design_of(apair.AChain(**d, base=B))
    np.testing.assert_allclose(framed.gravity, B[:3, :3].T @ d["gravity"], rtol=0, atol=1e-14)
    assert framed.dh == design.dh and specialise.frame_constants(chain) is None


@pytest.mark.slow
def test_frameless_code_is_unchanged():
    """The committed example (examples/codegen/chain4a) is what a chain without frames gets, byte
    for byte but for the content hash (which covers the code generator's own files); identity
    frames give the same code as none."""
    folder = ROOT / "examples" / "codegen" / "chain4a"
    chain = apair.load(ROOT / "examples" / "4a_chain.toml")
    files = specialise.render(chain, "chain4a", "4a_chain.toml", title=chain.name)
    old = json.loads((folder / "manifest.json").read_text())
    new = json.loads(files["manifest.json"])
    for rel, text in files.items():
        if rel != "manifest.json":
            assert (folder / rel).read_text().replace(old["content_hash"], new["content_hash"]) == text, rel
    old.pop("files")
    assert old == dict(new, content_hash=old["content_hash"]) and "frames" not in new
    d = random_design(np.random.default_rng(7), 2)
    ident = apair.AChain(**d, base=np.eye(4), tool=np.eye(4))
    assert specialise.render(ident, "ident", "ident.toml") == specialise.render(
        apair.AChain(**d), "ident", "ident.toml"
    )


def test_framed_output_is_deterministic_and_declares_the_frames():
    """Rendered twice, byte for byte the same; the header has the frames as initialisers (the
    exact doubles), the tool's functions and the frame-0 ones; the manifest lists both and the
    frames; with a tool translation, jacobian brings fk along (it needs frame n's rotation)."""
    framed, _plain, _ = framed_cases()["r2"]
    rng = np.random.default_rng(6)
    d = random_design(rng, 2, ("revolute",))
    offset = apair.AChain(**d, base=random_frame(rng), tool=random_frame(rng, 0.2))
    files = specialise.render(offset, "arm", "arm.toml", kernels=["jacobian"])
    assert files == specialise.render(offset, "arm", "arm.toml", kernels=["jacobian"])
    header = files["arm.h"]
    for fn in ("arm_fk(", "arm_fk_dh(", "arm_jacobian(", "arm_jacobian_dh(", "arm_jacobian_batch("):
        assert fn in header, fn
    assert "arm_fk_study" not in header and "arm_mass_matrix" not in header
    rows = header.split("#define arm_BASE { \\\n")[1].split("\n}")[0]
    values = [float(x) for x in rows.replace("\\", "").replace("\n", " ").split(",")]
    assert values == offset.base.ravel().tolist()
    manifest = json.loads(files["manifest.json"])
    assert sorted(manifest["kernels"]) == ["fk", "fk_dh", "jacobian", "jacobian_dh"]
    assert manifest["frames"]["tool"] == [[repr(x) for x in row] for row in offset.tool.tolist()]
    assert specialise.kernels_for(offset, ["jacobian"]) == ("fk", "jacobian")
    assert specialise.kernels_for(framed, ["jacobian"]) == ("jacobian",)  # a tool without translation
    # a rotation-only tool: the Jacobian is only rotated (no ω × r, no fk call)
    c = specialise.render(framed, "rot", "rot.toml", kernels=["jacobian"])["rot.c"]
    body = c.split("void rot_jacobian(")[1].split("\n}\n")[0]
    assert "rot_fk_dh" not in body and "rot_jacobian_dh(q, J0)" in body


def test_bad_frames_are_refused_with_one_line():
    for bad, what in (
        (np.eye(3), "base: expected a 4x4"),
        (np.diag([1.0, 1.0, -1.0, 1.0]), "base: the rotation part is a reflection"),
    ):
        with pytest.raises(ValueError, match=f"^{what}") as exc:
            specialise.check_frames(SimpleNamespace(_base_T=bad, _tool_T=None))
        assert "\n" not in str(exc.value)
    with pytest.raises(ValueError, match="^tool: last row"):
        specialise.frame_constants(SimpleNamespace(_base_T=None, _tool_T=np.ones((4, 4))))
