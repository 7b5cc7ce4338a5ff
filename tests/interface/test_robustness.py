"""Defects found by fuzzing and by a new user's trial: each test here failed before its fix.

General pairs with a < b at their range end, byte order and alignment at the binding, the content
hash over every compiled source, the first-use race of the kernel index, joint limits in
simulation, non-physical and extreme-scale designs, explicit limits checked when a chain is built.
"""

from __future__ import annotations

import math
import threading

import numpy as np
import pytest

import apair
from apair import kernels


def general_pairs_a_below_b(rng, count):
    """Random general pairs with a < b (a limited range of θ), including the issue's example."""
    out = [apair.APair(0.09553023287638954, 0.17399101182428575, leg_length=0.09553023287638954)]
    while len(out) < count:
        r_b, r_p = rng.uniform(0.02, 0.2, 2)
        lo = math.sqrt(max(r_b**2 + r_p**2 / 4 - r_b * r_p, 0.0))
        mid = math.sqrt(r_b**2 + r_p**2 / 4)  # a = 0
        L1 = rng.uniform(lo, mid) * (1 + 1e-6)
        out.append(apair.APair(r_b, r_p, leg_length=L1))
    return out


# ----------------------------------------------------------------------------- item 2
def test_general_pairs_with_a_below_b_have_collision_limits():
    rng = np.random.default_rng(14)
    for p in general_pairs_a_below_b(rng, 40):
        assert p.a < p.b and p.theta_limit is not None
        lo, hi, what = p.collision_limits()
        assert -p.theta_limit <= lo < 0 < hi <= p.theta_limit
        d = p.translation(np.array([lo, hi]))
        assert np.all(np.isfinite(d)) and np.all(d >= 0)
        assert what == "plates" or what.startswith("legs ")
        if hi < p.theta_limit - 1e-9:
            assert what.startswith("legs ")  # the plates meet only at the range end (d = 0)
        chain = apair.AChain([p], [0.1], [0.0])
        assert np.all(np.isfinite(chain.limits))


def test_translation_at_the_pairs_own_range_end():
    p = apair.APair(0.05, 0.04, leg_length=0.06)
    lim = p.theta_limit
    assert p.translation(lim) >= 0 and p.translation(-lim) >= 0
    assert p.translation(lim + 2 * np.pi) >= 0  # the range is periodic
    p.leg_endpoints(np.array([lim, -lim]))
    with pytest.raises(ValueError, match="theta: outside"):
        p.translation(lim + 1e-6)


def test_clearance_plot_of_a_general_pair(tmp_path):
    from apair import plots

    p = general_pairs_a_below_b(np.random.default_rng(2), 1)[0]
    assert plots.clearance(p, tmp_path / "g.png").stat().st_size > 0


# ----------------------------------------------------------------------------- item 3
needs_c = pytest.mark.skipif(not kernels.c_available(), reason="the C kernels are not installed")


@pytest.mark.parametrize("backend", ["c", "numpy"])
def test_big_endian_and_unaligned_inputs_give_the_same_numbers(backend):
    if backend == "c" and not kernels.c_available():
        pytest.skip("the C kernels are not installed")
    chain = apair.load("examples/4a_chain.toml")
    q = np.array([0.3, -0.5, 0.8, 1.1])
    law = chain._law(q)
    apair.set_backend(backend)
    try:
        ref = kernels.call("fk4", law, chain._dh)[0]
        raw = bytearray(law.nbytes + 1)
        unaligned = np.frombuffer(memoryview(raw)[1:], dtype=np.float64).reshape(law.shape)
        unaligned[:] = law
        assert not unaligned.flags.aligned
        for args in ((law.astype(">f8"), chain._dh), (unaligned, chain._dh), (law, chain._dh.astype(">f8"))):
            assert np.array_equal(kernels.call("fk4", *args)[0], ref)
        assert np.array_equal(chain.fk(q.astype(">f8")), chain.fk(q))
    finally:
        apair.set_backend(None)


def test_complex_kernel_inputs_are_refused_not_cast():
    chain = apair.load("examples/4a_chain.toml")
    q = np.array([0.3, -0.5, 0.8, 1.1])
    with pytest.raises(ValueError, match="law"):
        kernels.call("fk4", chain._law(q) + 1j, chain._dh)


# ----------------------------------------------------------------------------- item 4
def test_content_hash_covers_every_compiled_source():
    """A change to any generated C source (so to its template) changes APAIR_CONTENT_HASH, and the
    sources hash the binding was built with is the manifest's."""
    from pathlib import Path

    from codegen.emitter import sources_hash

    files = {p.name: p.read_text() for p in sorted(Path("generated/c").glob("*.[ch]"))}
    manifest = kernels.manifest()
    assert sources_hash(files) == manifest["sources_hash"]
    edited = dict(files, **{"law_sinusoidal.c": files["law_sinusoidal.c"] + "\n"})
    assert sources_hash(edited) != manifest["sources_hash"]
    if kernels.c_available():
        assert kernels._native()[0].sources_hash == manifest["sources_hash"]


@pytest.mark.slow
def test_header_hash_changes_with_the_kernel_template(monkeypatch):
    import codegen.emitter as E
    from derivations import apair_pair

    sets, specs, _ = apair_pair.derive()
    lowered = {"apair_pair": [E.lower(s) for s in specs]}
    before = E.Emitter().render(lowered, {})
    original = E.Emitter._template

    def edited(self, name):
        template, src = original(self, name)
        if name == "kernels.c.j2":
            template = self.env.from_string(src + "/* edited */\n")
        return template, src

    monkeypatch.setattr(E.Emitter, "_template", edited)
    after = E.Emitter().render(lowered, {})
    assert after["c/law_sinusoidal.c"] != before["c/law_sinusoidal.c"]
    assert after["c/apair.h"] != before["c/apair.h"]  # the header (with its hash) follows
    assert E.json.loads(after["manifest.json"])["content_hash"] != E.json.loads(before["manifest.json"])["content_hash"]


def test_binding_built_from_other_sources_is_refused(monkeypatch):
    if not kernels.c_available():
        pytest.skip("the C kernels are not installed")
    native = kernels._native()[0]
    kernels._native.cache_clear()
    fake = dict(kernels.manifest(), sources_hash="0" * 64)
    monkeypatch.setattr(kernels, "manifest", lambda: fake)
    try:
        module, why = kernels._native()
        assert module is None and "other generated C sources" in why
    finally:
        monkeypatch.undo()
        kernels._native.cache_clear()
        assert kernels._native()[0] is native


# ----------------------------------------------------------------------------- item 5
@needs_c
def test_first_use_of_the_kernel_index_from_many_threads():
    native = kernels._native()[0]
    errors = []
    for _ in range(20):
        kernels._c_table.cache_clear()
        barrier = threading.Barrier(8)

        def work():
            barrier.wait()
            try:
                kernels._c_index(native, "fk6")
            except Exception as exc:
                errors.append(exc)

        threads = [threading.Thread(target=work) for _ in range(8)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
    assert not errors


# ----------------------------------------------------------------------------- item 6
def test_free_motion_stops_at_the_first_joint_limit():
    chain = apair.load("examples/4a_chain.toml")
    t = np.linspace(0.0, 1.0, 101)
    traj = chain.simulate(np.zeros(4), np.zeros(4), t)
    stop = traj.stop
    assert stop is not None and stop.t < 1.0
    lim = chain.hard_limits()[stop.joint - 1, 0 if stop.side == "lower" else 1]
    assert stop.value == lim
    assert traj.t[-1] == stop.t and np.all(np.diff(traj.t) > 0)
    assert abs(traj.q[-1, stop.joint - 1] - lim) < 1e-8  # located to the integrator's tolerance
    inside = chain.within_limits(traj.q[:-1])
    assert inside.all()
    assert np.array_equal(traj.t[:-1], t[t < stop.t])
    assert f"joint {stop.joint}" in str(stop)
    free = chain.simulate(np.zeros(4), np.zeros(4), t, limits="ignore")
    assert free.stop is None and len(free.t) == len(t)
    assert np.abs(free.q).max() > np.abs(chain.hard_limits()).max()


def test_general_pair_run_ends_at_its_range_end_with_a_partial_trajectory():
    g = apair.APair(0.05, 0.04, leg_length=0.06)
    chain = apair.AChain(
        [g], [0.1], [0.0], links=[apair.Link(1.0, [0.05, 0, 0], np.eye(3) * 1e-3)], gravity=(0, -9.81, 0)
    )
    for limits in ("stop", "ignore"):
        traj = chain.simulate([0.5], [0.0], np.linspace(0, 2, 201), limits=limits)
        assert traj.stop is not None and traj.stop.joint == 1
        assert abs(abs(traj.q[-1, 0]) - g.theta_limit) < 1e-6
        assert len(traj.t) > 10 and np.isfinite(traj.energy).all()


def test_simulate_refuses_a_start_outside_the_limits():
    chain = apair.load("examples/4a_chain.toml")
    with pytest.raises(ValueError, match="q0: joint 4"):
        chain.simulate([0, 0, 0, 2.5], np.zeros(4), [0.0, 0.1])
    with pytest.raises(ValueError, match="limits"):
        chain.simulate(np.zeros(4), np.zeros(4), [0.0, 0.1], limits="bogus")


# ----------------------------------------------------------------------------- item 7
@pytest.mark.parametrize(
    "kwargs, name",
    [
        (dict(base_radius=0.05, platform_radius=0.05, leg_length=1e200), "leg_length"),
        (dict(base_radius=1e200, platform_radius=1e200), "base_radius"),
        (dict(base_radius=0.05, platform_radius=1e-200), "platform_radius"),
        (dict(base_radius=0.05, platform_radius=0.05, leg_radius=1e300), "leg_radius"),
        (dict(base_radius=0.05, platform_radius=0.05, thickness=1e-300), "thickness"),
    ],
)
def test_no_finite_answer_is_refused(kwargs, name):
    with pytest.raises(ValueError, match=f"^{name}: .* outside the range"):
        apair.APair(**kwargs)


@pytest.mark.parametrize("scale", [1e-37, 1e-20, 1.0, 1e20, 1e38])
def test_collision_limits_are_scale_invariant(scale):
    ref = apair.APair(0.05, 0.04, leg_radius=0.002, thickness=0.001).collision_limits()
    p = apair.APair(0.05 * scale, 0.04 * scale, leg_radius=0.002 * scale, thickness=0.001 * scale)
    lim = p.collision_limits()
    assert lim.what.split()[0] == ref.what.split()[0]  # (symmetric legs may tie)
    assert abs(lim.theta_max - ref.theta_max) < 1e-9 and abs(lim.theta_min - ref.theta_min) < 1e-9
    thin = apair.APair(scale, scale).collision_limits()
    assert abs(thin.theta_max - 2 * np.pi / 3) < 1e-6  # thin legs: axes cross at ±120° at every scale


def test_tiny_leg_radius_is_fast_and_equals_zero_radius():
    import time

    t0 = time.perf_counter()
    tiny = apair.APair(0.05, 0.04, leg_radius=1e-40).collision_limits()
    assert time.perf_counter() - t0 < 10  # was 131 s (huge exact denominators)
    zero = apair.APair(0.05, 0.04).collision_limits()
    assert abs(tiny.theta_max - zero.theta_max) < 1e-9


def test_repr_shows_every_parameter_off_its_default():
    p = apair.APair(0.05, 0.04, leg_mass=0.1, leg_radius=0.002, thickness=0.003)
    assert repr(p) == "APair(0.05, 0.04, leg_mass=0.1, leg_radius=0.002, thickness=0.003)"
    assert eval(repr(p), {"APair": apair.APair}).leg_radius == 0.002
    assert repr(apair.APair(0.05, 0.04)) == "APair(0.05, 0.04)"


# ----------------------------------------------------------------------------- item 11
def test_explicit_limits_beyond_the_collision_range_fail_when_built(tmp_path):
    p = apair.APair(0.05, 0.04)
    with pytest.raises(ValueError, match=r"limits\[0\]: .* beyond joint 1's collision-free range"):
        apair.AChain([p], [0.1], [0.0], limits=[(-3.0, 1.0)])
    f = tmp_path / "c.toml"
    f.write_text(
        '[[joint]]\npair = "sinusoidal"\nbase_radius = 0.05\nplatform_radius = 0.04\na = 0.1\n'
        "alpha = 0\nlimits_deg = [-170, 90]\n"
    )
    with pytest.raises(ValueError, match=r"joint 1\.limits_deg: \(-170, 90\) deg goes beyond .* \(-120, 120\) deg"):
        apair.load(f)
