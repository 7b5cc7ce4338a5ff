"""Layer 5: the generated C is a standalone library: it builds cleanly with gcc and clang, at -O0
and -O3, as C99 and as C++17, runs clean under ASan/UBSan, and builds with a plain cc command
line, with CMake (add_subdirectory, or installed and found by find_package) and with pkg-config.

The driver is written from generated/manifest.json: it calls every kernel, single, batched (with a
shared, stride-0 input) and through the registry, and checks them against each other. The example
program (examples/c/chain_4a.c) is checked number by number against the Python runtime.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
import tomllib
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest
import sysdeps  # tests/sysdeps.py: clang, and the packages that bring it

ROOT = Path(__file__).resolve().parents[2]
CDIR = ROOT / "generated" / "c"
MANIFEST = json.loads((ROOT / "generated" / "manifest.json").read_text())
STRICT = ["-Wall", "-Wextra", "-Werror", "-pedantic"]
SOURCES = sorted(str(p) for p in CDIR.glob("*.c"))
MANIFEST_VERSION = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["version"]

pytestmark = pytest.mark.skipif(shutil.which("gcc") is None, reason="gcc is required")


def run(cmd, **kw):
    res = subprocess.run(cmd, capture_output=True, text=True, **kw)
    assert res.returncode == 0, f"{' '.join(map(str, cmd))}\n{res.stdout}\n{res.stderr}"
    return res


def size(shape) -> int:
    n = 1
    for s in shape:
        n *= s
    return n


def driver_source() -> str:
    """A C program that exercises every kernel and exits non-zero on a mismatch or a non-finite value."""
    prefix = MANIFEST["prefix"]
    lines = [
        "#include <math.h>",
        "#include <stdio.h>",
        "#include <stdlib.h>",
        '#include "apair.h"',
        "",
        "static double val(int i) { return 0.1 + 0.5 * (double)((i * 7919) % 101) / 101.0; }",
        "",
    ]
    count = 5
    names = sorted(MANIFEST["kernels"])
    # one external function per kernel (a static one called once is inlined into main): the optimisers
    # are superlinear in a function's size, and one main of every kernel took clang 105 s at -O3
    for name in names:
        k = MANIFEST["kernels"][name]
        lines += [f"int check_{name}(void);", f"int check_{name}(void)", "{", "    int failures = 0;", "    int i, k;"]
        lines.append("    {")
        for j, a in enumerate(k["inputs"]):
            n = size(a["shape"])
            # the first input varies over the batch, the others are shared (stride 0)
            total = n * count if j == 0 else n
            lines.append(f"        double in{j}[{total}];")
            lines.append(f"        for (i = 0; i < {total}; ++i) in{j}[i] = val(i + {31 * j});")
            if a["name"] == "links":  # a heavy diagonal of each inertia: M positive definite
                lines.append(f"        for (i = 0; i < {total}; ++i) if (i % 10 >= 4 && i % 10 <= 6) in{j}[i] += 2.0;")
        for j, a in enumerate(k["outputs"]):
            n = size(a["shape"])
            lines.append(f"        double out{j}[{n * count}], one{j}[{n}], batch{j}[{n * count}];")
            lines.append(f"        for (i = 0; i < {n * count}; ++i) out{j}[i] = NAN;")
        ins = lambda off: ", ".join(
            f"in{j} + {off if j == 0 else 0} * {size(a['shape'])}" for j, a in enumerate(k["inputs"])
        )
        strided = ", ".join(f"in{j}, {size(a['shape']) if j == 0 else 0}" for j, a in enumerate(k["inputs"]))
        outs_b = ", ".join(f"out{j}" for j in range(len(k["outputs"])))
        outs_1 = ", ".join(f"one{j}" for j in range(len(k["outputs"])))
        lines.append(f"        {prefix}{name}_batch({count}, {strided}, {outs_b});")
        lines.append(f"        for (k = 0; k < {count}; ++k) {{")
        lines.append(f"            {prefix}{name}({ins('k')}, {outs_1});")
        for j, a in enumerate(k["outputs"]):
            n = size(a["shape"])
            lines.append(f"            for (i = 0; i < {n}; ++i) {{")
            lines.append(f"                if (!isfinite(one{j}[i]) || one{j}[i] != out{j}[k * {n} + i]) {{")
            lines.append(f'                    printf("{name}: item %d entry %d\\n", k, i); ++failures;')
            lines.append("                }")
            lines.append("            }")
        lines.append("        }")
        # the registry entry gives the same numbers through its uniform entry points
        n_in, n_out = len(k["inputs"]), len(k["outputs"])
        lines.append("        {")
        lines.append(f'            const {prefix}kernel *r = {prefix}find_kernel("{name}");')
        lines.append(f"            const double *rin[{n_in}];")
        lines.append(f"            double *rout[{n_out}];")
        lines.append(f"            ptrdiff_t rstride[{n_in}];")
        for j, a in enumerate(k["inputs"]):
            lines.append(f"            rin[{j}] = in{j};")
            lines.append(f"            rstride[{j}] = {size(a['shape']) if j == 0 else 0};")
        lines.append(f"            if (r == NULL || r->n_inputs != {n_in} || r->n_outputs != {n_out}) {{")
        lines.append(f'                printf("{name}: registry entry\\n"); ++failures;')
        lines.append("            } else {")
        for j, a in enumerate(k["outputs"]):
            lines.append(
                f'                if (r->outputs[{j}].size != {size(a["shape"])}) {{ printf("{name}: size\\n"); ++failures; }}'
            )
            lines.append(f"                rout[{j}] = one{j};")
        lines.append("                r->eval(rin, rout);")
        for j, a in enumerate(k["outputs"]):
            n = size(a["shape"])
            lines.append(
                f'                for (i = 0; i < {n}; ++i) if (one{j}[i] != out{j}[i]) {{ printf("{name}: eval\\n"); ++failures; break; }}'
            )
        # the split form (invariants once, then the core) gives the same numbers to the bit
        lines.append("                if (r->n_invariants > 0) {")
        lines.append("                    double *inv = (double *)malloc(sizeof(double) * (size_t)r->n_invariants);")
        for j, a in enumerate(k["outputs"]):
            lines.append(f"                    rout[{j}] = one{j};")
            lines.append(f"                    for (i = 0; i < {size(a['shape'])}; ++i) one{j}[i] = 0.0;")
        lines.append("                    r->invariants(rin, inv);")
        lines.append("                    r->core(inv, rin, rout);")
        for j, a in enumerate(k["outputs"]):
            n = size(a["shape"])
            lines.append(
                f'                    for (i = 0; i < {n}; ++i) if (one{j}[i] != out{j}[i]) {{ printf("{name}: core\\n"); ++failures; break; }}'
            )
        lines.append("                    free(inv);")
        lines.append("                } else if (r->invariants != NULL || r->core != NULL) {")
        lines.append(f'                    printf("{name}: split form without invariants\\n"); ++failures;')
        lines.append("                }")
        for j in range(len(k["outputs"])):
            lines.append(f"                rout[{j}] = batch{j};")
        lines.append(f"                r->eval_batch({count}, rin, rstride, rout);")
        for j, a in enumerate(k["outputs"]):
            n = size(a["shape"]) * count
            lines.append(
                f'                for (i = 0; i < {n}; ++i) if (batch{j}[i] != out{j}[i]) {{ printf("{name}: eval_batch\\n"); ++failures; break; }}'
            )
        lines.append("            }")
        lines.append("        }")
        lines.append("    }")
        lines += ["    return failures;", "}", ""]
    lines += ["int main(void)", "{", "    int failures = 0;"]
    lines += [f"    failures += check_{name}();" for name in names]
    lines += [
        f'    if ({prefix}find_kernel("no_such_kernel") != NULL) {{ printf("registry: unknown name found\\n"); ++failures; }}',
        '    if (failures == 0) printf("ok\\n");',
        "    return failures != 0;",
        "}",
        "",
    ]
    return "\n".join(lines)


@pytest.fixture(scope="module")
def driver(tmp_path_factory) -> Path:
    d = tmp_path_factory.mktemp("cdriver")
    path = d / "driver.c"
    path.write_text(driver_source())
    return path


@pytest.mark.slow
def test_strict_c99_compiles():
    """(make lib builds the same sources with these flags at -O2.)"""
    for src in SOURCES:
        run(["gcc", "-std=c99", *STRICT, "-O0", "-c", src, "-o", "/dev/null"])


# (compiler, language, optimisation, sanitizers): gcc and clang, -O0 and -O3, C99 and C++17, and
# AddressSanitizer + UndefinedBehaviorSanitizer, each at least once. Never -ffast-math (apair.h).
CONFIGS = [
    ("gcc", "c99", "-O0", True),
    ("gcc", "c99", "-O3", False),
    ("g++", "c++17", "-O0", False),
    ("clang", "c99", "-O0", True),
    ("clang", "c99", "-O3", False),
    ("clang++", "c++17", "-O3", False),
]
SANITIZE = ["-fsanitize=address,undefined", "-fno-sanitize-recover=all", "-fno-omit-frame-pointer"]
SAN_ENV = {"ASAN_OPTIONS": "detect_leaks=1:abort_on_error=1", "UBSAN_OPTIONS": "halt_on_error=1"}
EXAMPLE = ROOT / "examples" / "c" / "chain_4a.c"


def test_clang_skip_messages_and_the_readme_name_the_same_packages():
    """Where clang is missing the clang configurations are skipped with the command that installs
    it, and the README's set-up names that command: the same Debian packages that `make clang`
    (tests/sysdeps.py) installs."""
    command = sysdeps.apt_command(sysdeps.CLANG_PACKAGES)
    assert "clang" in sysdeps.CLANG_PACKAGES and "libclang-rt-dev" in sysdeps.CLANG_PACKAGES  # ASan, UBSan
    assert command in sysdeps.clang_skip_reason("clang is not installed")
    readme = " ".join((ROOT / "README.md").read_text().split())
    assert f"`{command}`" in readme
    makefile = (ROOT / "Makefile").read_text()
    assert re.search(r"^test: .*\bclang\b", makefile, re.M), "make test does not install clang"


def tool(name: str) -> str | None:
    """A build tool from the environment's own bin folder (the test extra installs cmake and
    pkgconf there), else from PATH."""
    local = Path(sys.executable).parent / name
    return str(local) if local.exists() else shutil.which(name)


def build(compiler, lang, opt, sanitize, programs, out: Path) -> dict[str, Path]:
    """Compile the library sources and each program (in parallel, one object per source) and link
    one executable per program; returns {program stem: executable}."""
    flags = ["-std=" + lang, *STRICT, opt, f"-I{CDIR}"] + (SANITIZE if sanitize else [])
    lang_flag = ["-x", "c++"] if lang.startswith("c++") else []
    out.mkdir(parents=True, exist_ok=True)
    sources = [Path(s) for s in SOURCES] + [Path(p) for p in programs]
    objects = {src: out / f"{src.stem}.o" for src in sources}
    with ThreadPoolExecutor(max_workers=2) as pool:
        list(
            pool.map(lambda src: run([compiler, *lang_flag, *flags, "-c", str(src), "-o", str(objects[src])]), sources)
        )
    lib = [str(objects[Path(s)]) for s in SOURCES]
    exes = {}
    for p in map(Path, programs):
        exe = out / p.stem
        run([compiler, *flags, str(objects[p]), *lib, "-o", str(exe), "-lm"])
        exes[p.stem] = exe
    return exes


def sanitizers_link(compiler: str, tmp: Path) -> bool:
    """Whether the compiler can link a program with ASan and UBSan (their runtimes are separate
    packages for clang on some distributions)."""
    src = tmp / "probe.c"
    src.write_text("int main(void) { return 0; }\n")
    res = subprocess.run([compiler, *SANITIZE, str(src), "-o", str(tmp / "probe")], capture_output=True)
    return res.returncode == 0


def python_state(rng):
    """The example chain and a random state: (chain, q, qd, qdd)."""

    import apair

    chain = apair.load(ROOT / "examples" / "4a_chain.toml")
    return chain, rng.uniform(-1, 1, 4), rng.uniform(-1, 1, 4), rng.uniform(-1, 1, 4)


def check_example(exe, env=None) -> None:
    """Run the example program at a random state and compare every number with the runtime."""
    import numpy as np

    chain, q, qd, qdd = python_state(np.random.default_rng(7))
    res = run([str(exe), *(repr(float(x)) for x in (*q, *qd, *qdd))], env=env)
    lines = res.stdout.splitlines()
    assert lines[0].startswith("apair ") and MANIFEST["content_hash"] in lines[0]
    got = {line.split()[0]: np.array([float(x) for x in line.split()[1:]]) for line in lines[1:]}
    np.testing.assert_allclose(got["T"].reshape(4, 4), chain.fk(q), rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(got["J"].reshape(6, 4), chain.jacobian(q), rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(got["tau"], chain.inverse_dynamics(q, qd, qdd), rtol=1e-12, atol=1e-12)
    if env is not None:
        assert res.stderr == ""


@pytest.mark.slow
@pytest.mark.parametrize("compiler, lang, opt, sanitize", CONFIGS, ids=lambda v: str(v))
def test_library_driver_and_example_across_compilers(compiler, lang, opt, sanitize, driver, tmp_path):
    """Every kernel single, batched and through the registry (the driver), and the example
    program against the Python runtime, for one compiler configuration."""
    clang = compiler.startswith("clang")
    if shutil.which(compiler) is None:
        pytest.skip(
            sysdeps.clang_skip_reason(f"{compiler} is not installed") if clang else f"{compiler} is not installed"
        )
    if sanitize and not sanitizers_link(compiler, tmp_path):
        why = f"{compiler} has no sanitizer runtime"
        pytest.skip(sysdeps.clang_skip_reason(why) if clang else why)
    exes = build(compiler, lang, opt, sanitize, [driver, EXAMPLE], tmp_path)
    env = SAN_ENV if sanitize else None
    res = run([str(exes["driver"])], env=env)
    assert res.stdout.strip() == "ok"
    if sanitize:
        assert res.stderr == ""
    check_example(exes["chain_4a"], env=env)


@pytest.mark.slow
def test_plain_cc_command_line_builds_the_example(tmp_path):
    """The README's one-line build: no Python, no build system."""
    exe = tmp_path / "chain_4a"
    run(["cc", "-std=c99", f"-I{CDIR}", str(EXAMPLE), *SOURCES, "-o", str(exe), "-lm"])
    check_example(exe)


@pytest.fixture(scope="module")
def cmake():
    path = tool("cmake")
    if path is None:
        pytest.fail("cmake is missing: it is in the test extra (pip install .[test])")
    return path


@pytest.mark.slow
def test_cmake_add_subdirectory_builds_the_example(cmake, tmp_path):
    build_dir = tmp_path / "build"
    run([cmake, "-S", str(ROOT / "examples" / "c"), "-B", str(build_dir)])
    run([cmake, "--build", str(build_dir), "--parallel", "2"])
    check_example(build_dir / "chain_4a")


@pytest.mark.slow
def test_cmake_install_serves_find_package_and_pkg_config(cmake, tmp_path):
    """Install the library, then build the example against it with find_package(apair) and with
    the flags pkg-config gives."""
    prefix = tmp_path / "prefix"
    run([cmake, "-S", str(CDIR), "-B", str(tmp_path / "lib")])  # the README's recipe: prefix at install time
    run([cmake, "--build", str(tmp_path / "lib"), "--parallel", "2"])
    run([cmake, "--install", str(tmp_path / "lib"), "--prefix", str(prefix)])
    assert (prefix / "include" / "apair.h").exists()
    consumer = tmp_path / "consumer"
    consumer.mkdir()
    (consumer / "CMakeLists.txt").write_text(
        "cmake_minimum_required(VERSION 3.13)\nproject(consumer LANGUAGES C)\n"
        f"find_package(apair {MANIFEST_VERSION} CONFIG REQUIRED)\n"
        f"add_executable(chain_4a {EXAMPLE.as_posix()})\ntarget_link_libraries(chain_4a PRIVATE apair::apair)\n"
    )
    run([cmake, "-S", str(consumer), "-B", str(consumer / "build"), f"-DCMAKE_PREFIX_PATH={prefix}"])
    run([cmake, "--build", str(consumer / "build")])
    check_example(consumer / "build" / "chain_4a")

    pkg_config = tool("pkg-config") or tool("pkgconf")
    if pkg_config is None:
        pytest.fail("pkg-config is missing: pkgconf is in the test extra (pip install .[test])")
    pc_dirs = [str(p.parent) for p in prefix.rglob("apair.pc")]
    assert pc_dirs, "no apair.pc installed"
    env = dict(os.environ, PKG_CONFIG_PATH=os.pathsep.join(pc_dirs))
    flags = run([pkg_config, "--cflags", "--libs", "apair"], env=env).stdout.split()
    assert run([pkg_config, "--modversion", "apair"], env=env).stdout.strip() == MANIFEST_VERSION
    exe = tmp_path / "chain_4a_pc"
    run(["cc", "-std=c99", str(EXAMPLE), *flags, "-o", str(exe)])
    check_example(exe)
    # relocatable: the installed tree moved elsewhere still gives flags that point into it
    moved = tmp_path / "moved"
    prefix.rename(moved)
    env = dict(os.environ, PKG_CONFIG_PATH=os.pathsep.join(str(p.parent) for p in moved.rglob("apair.pc")))
    flags = run([pkg_config, "--cflags", "--libs", "apair"], env=env).stdout.split()
    assert any(f.startswith("-I") and Path(f[2:]).resolve() == (moved / "include").resolve() for f in flags), flags


# A parent project of apair codegen's CMakeLists (examples/codegen/chain4a, by add_subdirectory):
# its top-level lines after project(), its cache options, and how many tests ctest finds in the
# parent's build folder. "own": the chain's folder built on its own, no parent.
CHAIN_CODE = ROOT / "examples" / "codegen" / "chain4a"
PARENTS = {
    "own": (None, [], 1),
    "enable_testing": ("enable_testing()\nadd_subdirectory(chain4a)\n", [], 1),
    "include_ctest": ("include(CTest)\nadd_subdirectory(chain4a)\n", [], 1),
    "enable_testing_after": ("add_subdirectory(chain4a)\nenable_testing()\n", [], 1),
    "testing_off": ("include(CTest)\nadd_subdirectory(chain4a)\n", ["-DBUILD_TESTING=OFF"], 0),
    "no_testing": ("add_subdirectory(chain4a)\n", [], 0),
}


def test_readme_names_every_file_apair_codegen_writes():
    """The README's paragraph on `apair codegen ... --prefix arm4` names each file that apair
    codegen writes: those of examples/codegen/chain4a (the example chain's, --prefix chain4a, which
    make check compares with a fresh run)."""
    readme = (ROOT / "README.md").read_text()
    paragraph = re.search(r"^`apair codegen .*?(?:\n\n|\Z)", readme, re.M | re.S).group(0)
    written = sorted(p.name.replace("chain4a", "arm4") for p in CHAIN_CODE.iterdir())
    assert "manifest.json" in written and len(written) == 7
    assert [f for f in written if f"`{f}`" not in paragraph] == []


def ctest_count(ctest: str, folder: Path) -> int:
    out = run([ctest, "-N"], cwd=folder).stdout
    return int(out.rsplit("Total Tests:", 1)[1].split()[0])


@pytest.mark.slow
@pytest.mark.parametrize("parent", PARENTS)
def test_chain_code_self_test_runs_under_ctest(cmake, parent, tmp_path):
    """apair codegen's CMakeLists: ctest runs the chain's self-test from its own build folder, and
    from a parent's under add_subdirectory when the parent enables testing (before or after
    add_subdirectory, by enable_testing() or include(CTest)), never with BUILD_TESTING=OFF. Under
    add_subdirectory the chain leaves CTest's dashboard set-up (include(CTest): DartConfiguration.tcl,
    the Experimental targets) to the parent, and its header says what the parent must call."""
    ctest = tool("ctest")
    if ctest is None:
        pytest.fail("ctest is missing: the cmake package of the test extra has it (pip install .[test])")
    header = (CHAIN_CODE / "CMakeLists.txt").read_text().split("cmake_minimum_required")[0]
    assert "enable_testing() or include(CTest)" in " ".join(header.replace("#", " ").split())
    lines, options, count = PARENTS[parent]
    if lines is None:
        src, sub = CHAIN_CODE, None
    else:
        src = tmp_path / "parent"
        shutil.copytree(CHAIN_CODE, src / "chain4a")
        (src / "CMakeLists.txt").write_text(
            "cmake_minimum_required(VERSION 3.13)\nproject(parent LANGUAGES C)\n" + lines
        )
        sub = "chain4a"
    build = tmp_path / "build"
    run([cmake, "-S", str(src), "-B", str(build), *options])
    run([cmake, "--build", str(build), "--parallel", "2"])
    assert ctest_count(ctest, build) == count
    if count:
        assert "100% tests passed" in run([ctest, "--output-on-failure"], cwd=build).stdout
    if sub is not None:
        assert not (build / sub / "DartConfiguration.tcl").exists()
        # in the chain's own build folder the test is there whenever testing is not switched off
        assert ctest_count(ctest, build / sub) == (0 if "-DBUILD_TESTING=OFF" in options else 1)


@pytest.mark.slow
def test_driver_detects_a_broken_kernel(driver, tmp_path):
    """The driver's check can fail: a kernel whose batch disagrees with its single call is caught."""
    broken = tmp_path / "broken.c"
    loop = "for (k = 0; k < count; ++k) {"
    first = next(s for s in SOURCES if loop in Path(s).read_text())  # a kernel's source
    src = Path(first).read_text()
    # make the first batch function skip its first item
    src = src.replace(loop, "for (k = 1; k < count; ++k) {", 1)
    broken.write_text(src)
    exe = tmp_path / "driver_broken"
    others = [s for s in SOURCES if s != first]
    run(["gcc", "-std=c99", "-O0", f"-I{CDIR}", str(broken), *others, str(driver), "-o", str(exe), "-lm"])
    res = subprocess.run([str(exe)], capture_output=True, text=True)
    assert res.returncode != 0 and "item 0" in res.stdout


def test_no_allocation_io_or_mutable_state_in_the_library():
    """Real-time use: no allocation, no I/O and no writable file-scope state in any source."""
    import re

    for path in [CDIR / "apair.h", *map(Path, SOURCES)]:
        text = path.read_text()
        assert not re.search(r"\b(malloc|calloc|realloc|free|alloca|printf|fopen|exit|abort)\s*\(", text), path
        for line in text.splitlines():
            if re.match(r"^static\s+(inline\s+)?(const\s+)?[A-Za-z_][\w\s\*]*\b\w+\(", line):
                continue  # a function of file scope, not state
            if re.match(r"^(double|int|float|char|size_t)\s+\**\w+\([^=]*\);\s*$", line):
                continue  # a function's prototype on one line, not state
            if line.startswith(("static ", "extern ")) or re.match(
                r"^(double|int|float|char|size_t)\b.*[=;]\s*$", line
            ):
                assert line.startswith(("static void", "static const", "extern const", 'extern "C"')), (path, line)


@pytest.mark.slow
def test_a_program_links_only_the_kernels_it_calls(tmp_path):
    """One source per kernel: a firmware build that calls inverse_dynamics4 from the static library
    takes that kernel's object alone (not the whole library), and one that calls forward_dynamics4
    takes it with the two kernels it calls (mass matrix and inverse dynamics), nothing else."""
    objects = tmp_path / "obj"
    objects.mkdir()
    # -O0: which objects the linker takes does not depend on the optimisation (-O1 took 45 s more)
    with ThreadPoolExecutor(max_workers=2) as pool:
        list(
            pool.map(
                lambda s: run(
                    [
                        "gcc",
                        "-std=c99",
                        *STRICT,
                        "-O0",
                        f"-I{CDIR}",
                        "-c",
                        s,
                        "-o",
                        str(objects / (Path(s).stem + ".o")),
                    ]
                ),
                SOURCES,
            )
        )
    archive = tmp_path / "libapair.a"
    run(["ar", "rcs", str(archive), *sorted(str(p) for p in objects.glob("*.o"))])
    internal = lambda k: [f"apair_internal_{k}_core", f"apair_internal_{k}_invariants"]
    public = lambda k: [f"apair_{k}", f"apair_{k}_batch", f"apair_{k}_core", f"apair_{k}_invariants"]
    cases = {
        "apair_inverse_dynamics4(law, qd, qdd, dh, turning, links, legs, g, out);": public("inverse_dynamics4")
        + internal("inverse_dynamics4"),
        "apair_forward_dynamics4(law, qd, qdd, dh, turning, links, legs, g, out);": public("forward_dynamics4")
        + internal("inverse_dynamics4")
        + internal("mass_matrix4")
        + public("inverse_dynamics4")
        + public("mass_matrix4"),
    }
    for call, expected in cases.items():
        program = tmp_path / "prog.c"
        program.write_text(
            '#include "apair.h"\nint main(void)\n{\n    double law[20] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, '
            "1, 0, 0, 0, 0}, qd[4] = {0}, qdd[4] = {0}, dh[16] = {0}, turning[4] = {1, 1, 1, 1}, links[40] = {0}, "
            "legs[12] = {0}, "
            "g[3] = {0, 0, -9.81}, out[4];\n    int i;\n    for (i = 0; i < 4; ++i) {\n"
            "        links[10 * i] = links[10 * i + 4] = links[10 * i + 5] = links[10 * i + 6] = 1.0;\n    }\n"
            f"    {call}\n    return out[0] != out[0];\n}}\n"
        )
        exe = tmp_path / "prog"
        run(["gcc", "-std=c99", f"-I{CDIR}", str(program), str(archive), "-lm", "-o", str(exe)])
        assert subprocess.run([str(exe)]).returncode == 0
        symbols = run(["nm", str(exe)]).stdout
        defined = sorted(line.split()[-1] for line in symbols.splitlines() if " T apair_" in line)
        assert defined == sorted(expected)
        assert exe.stat().st_size < 200_000


def c_array(name: str, a, ctype: str = "double") -> str:
    import numpy as np

    flat = np.asarray(a).ravel()
    body = ", ".join(repr(float(x)) if ctype == "double" else str(int(x)) for x in flat) or "0"
    return f"static const {ctype} {name}[{max(len(flat), 1)}] = {{{body}}};"


@pytest.mark.slow
def test_ik4_kernels_under_sanitizers(tmp_path):
    """apair_ik4_pencil, apair_ik4_screen and apair_ik4_left on one pose of a random 4A design,
    built with ASan and UBSan: no finding, and the numbers of the runtime's own build."""
    import numpy as np

    import apair
    from apair import ik
    from apair.ik import elimination4, joints, pencil, poses
    from apair.study import conjugate, multiply

    native = elimination4.native_in_use()
    if native is None:
        pytest.skip("the compiled C kernels are not installed")
    if not sanitizers_link("gcc", tmp_path):
        pytest.skip("gcc has no sanitizer runtime here")
    rng = np.random.default_rng(12)
    pairs = [apair.APair(*rng.uniform(0.05, 0.12, 2)) for _ in range(4)]
    chain = apair.AChain(pairs, rng.uniform(0.1, 0.5, 4), rng.uniform(-1.5, 1.5, 4), rng.uniform(-0.2, 0.2, 4))
    solver = ik.Solver(chain)
    elim = solver._elimination(False)
    a, b = elim._tries(True)[0]
    Qf, Qg = elim.combinations[a + 1], elim.combinations[b + 1]
    af, ag = elim._factor_array(a + 1), elim._factor_array(b + 1)
    # a pose whose screen meets a two-dimensional null space too (status 3), where one of 100 has
    # one: whether any does depends on the last bits of LAPACK's eigenvalues on this processor (none
    # of 1000 on some), so else the first pose with an accepted root (status 0)
    first = None
    for _ in range(100):
        target = poses.study_point(chain.fk(rng.uniform(-np.pi, np.pi, 4)))
        target[4:] /= solver.scale
        if elim.pre is not None:
            target = multiply(elim.pre, conjugate(target))
        C = np.ascontiguousarray(elim.image @ joints.left_matrix(target).T)
        f, g, M = native.ik4_pencil(C, Qf, af, Qg, ag, pencil.LEAD_COND, 3, pencil.DEFLATE_TOL)
        u3 = np.linalg.eigvals(M)
        u3 = np.sort(u3[np.abs(u3.imag) <= 1e-6].real)
        N = f.shape[1] + g.shape[1] - 2
        screen = native.ik4_screen(u3, C, f, g, elim.Q, pencil.PROBE[:N], elimination4._SCREEN_TOL)
        if np.any(screen[0] == 0):
            first = first or (C, f, g, M, u3, N, screen)
            if np.any(screen[0] == 3):
                break
    else:
        C, f, g, M, u3, N, screen = first
    W = screen[2][screen[0] == 0]
    j2 = elim.joints[1]
    joint = np.array([0.0, j2.delta, j2.offset, j2.sign])
    left = native.ik4_left(W, elim.Zmap, j2.P, joint, elimination4.LEFT_TOL)
    assert len(W) >= 1 and np.all(left[0] != 1)
    d3, d4 = C.shape[0] - 1, C.shape[1] - 1
    src = "\n".join(
        [
            "#include <stdio.h>",
            '#include "apair.h"',
            c_array("C", C),
            c_array("Qf", Qf),
            c_array("Qg", Qg),
            c_array("af", af, "int"),
            c_array("ag", ag, "int"),
            c_array("u3", u3),
            c_array("Q", elim.Q),
            c_array("probe", pencil.PROBE[:N]),
            c_array("stol", elimination4._SCREEN_TOL),
            c_array("W", W),
            c_array("Zmap", elim.Zmap),
            c_array("P2", j2.P),
            c_array("joint", joint),
            c_array("ltol", elimination4.LEFT_TOL),
            "static double f[289], g[289], M[512 * 512], u4[64], Wo[512], rel[64], u1[64], u2[128];",
            "static double two[256], W2[1024], rel2[128];",
            "static int status[64], lstatus[64], ok[128], two_ok[128];",
            "/* these kernels use no other: the registry stays out of this build */",
            "const apair_kernel *apair_find_kernel(const char *name) { (void)name; return NULL; }",
            "int main(void) {",
            "    int size = 0, i;",
            f"    if (apair_ik4_pencil({d3}, {d4}, C, Qf, af, Qg, ag, {pencil.LEAD_COND!r}, 3, {pencil.DEFLATE_TOL!r}, f, g, M, &size)) return 1;",
            '    printf("size %d\\nM", size);',
            '    for (i = 0; i < size * size; i++) printf(" %.17g", M[i]);',
            f"    if (apair_ik4_screen({len(u3)}, u3, {d3}, {d4}, C, f, {f.shape[0] - 1}, {f.shape[1] - 1}, g, "
            f"{g.shape[0] - 1}, {g.shape[1] - 1}, {len(elim.Q)}, Q, probe, stol, status, u4, Wo, rel, two, two_ok, W2, rel2))"
            " return 2;",
            f'    printf("\\ntwo"); for (i = 0; i < {4 * len(u3)}; i++) printf(" %.17g", two[i]);',
            f'    printf("\\nrel2"); for (i = 0; i < {2 * len(u3)}; i++) printf(" %.17g", rel2[i]);',
            f'    printf("\\nu4"); for (i = 0; i < {len(u3)}; i++) printf(" %.17g", u4[i]);',
            f'    printf("\\nstatus"); for (i = 0; i < {len(u3)}; i++) printf(" %d", status[i]);',
            f"    if (apair_ik4_left({len(W)}, W, {elim.Zmap.shape[0] - 1}, Zmap, {j2.P.shape[0] - 1}, P2, joint, ltol, "
            "lstatus, u1, u2, ok)) return 3;",
            f'    printf("\\nu1"); for (i = 0; i < {len(W)}; i++) printf(" %.17g", u1[i]);',
            f'    printf("\\nu2"); for (i = 0; i < {2 * len(W)}; i++) printf(" %.17g", u2[i]);',
            '    printf("\\n");',
            "    return 0;",
            "}",
            "",
        ]
    )
    prog = tmp_path / "ik4.c"
    prog.write_text(src)
    exe = tmp_path / "ik4"
    run(
        [
            "gcc",
            "-std=c99",
            *STRICT,
            "-O1",
            *SANITIZE,
            f"-I{CDIR}",
            str(prog),
            str(CDIR / "apair_ik4.c"),
            "-lm",
            "-o",
            str(exe),
        ]
    )
    res = run([str(exe)], env={**os.environ, **SAN_ENV})
    assert res.stderr == ""
    out = {line.split()[0]: line.split()[1:] for line in res.stdout.splitlines()}
    assert int(out["size"][0]) == len(M)
    np.testing.assert_allclose(np.array(out["M"], float).reshape(M.shape), M, rtol=1e-12, atol=1e-12 * np.abs(M).max())
    np.testing.assert_allclose(np.array(out["u4"], float), screen[1], rtol=1e-9, atol=1e-12)
    assert [int(s) for s in out["status"]] == screen[0].tolist()
    np.testing.assert_allclose(np.array(out["two"], float), screen[4].ravel(), rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(np.array(out["rel2"], float), screen[7].ravel(), rtol=1e-6, atol=1e-15)
    np.testing.assert_allclose(np.array(out["u1"], float), left[1], rtol=1e-10)
    np.testing.assert_allclose(np.array(out["u2"], float), left[2].ravel(), rtol=1e-10)
