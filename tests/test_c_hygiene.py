"""Layer 5: the generated C builds cleanly (C99 strict, and as C++) and runs clean under ASan/UBSan.

The driver is written from generated/manifest.json: it calls every kernel, single and batched
(with a shared, stride-0 input), and checks the batch against the single calls.
"""
from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
CDIR = ROOT / "generated" / "c"
MANIFEST = json.loads((ROOT / "generated" / "manifest.json").read_text())
STRICT = ["-Wall", "-Wextra", "-Werror", "-pedantic"]
SOURCES = sorted(str(p) for p in CDIR.glob("*.c"))

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
    lines = ['#include <math.h>', '#include <stdio.h>', '#include "apair.h"', "",
             "static double val(int i) { return 0.1 + 0.5 * (double)((i * 7919) % 101) / 101.0; }", "",
             "int main(void)", "{", "    int failures = 0;", "    int i, k;"]
    count = 5
    for name, k in sorted(MANIFEST["kernels"].items()):
        lines.append("    {")
        for j, a in enumerate(k["inputs"]):
            n = size(a["shape"])
            # the first input varies over the batch, the others are shared (stride 0)
            total = n * count if j == 0 else n
            lines.append(f"        double in{j}[{total}];")
            lines.append(f"        for (i = 0; i < {total}; ++i) in{j}[i] = val(i + {31 * j});")
        for j, a in enumerate(k["outputs"]):
            n = size(a["shape"])
            lines.append(f"        double out{j}[{n * count}], one{j}[{n}];")
            lines.append(f"        for (i = 0; i < {n * count}; ++i) out{j}[i] = NAN;")
        ins = lambda off: ", ".join(f"in{j} + {off if j == 0 else 0} * {size(a['shape'])}" for j, a in enumerate(k["inputs"]))
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
        lines.append("    }")
    lines += ['    if (failures == 0) printf("ok\\n");', "    return failures != 0;", "}", ""]
    return "\n".join(lines)


@pytest.fixture(scope="module")
def driver(tmp_path_factory) -> Path:
    d = tmp_path_factory.mktemp("cdriver")
    path = d / "driver.c"
    path.write_text(driver_source())
    return path


def test_strict_c99_compiles():
    """(make lib builds the same sources with these flags at -O2.)"""
    for src in SOURCES:
        run(["gcc", "-std=c99", *STRICT, "-O0", "-c", src, "-o", "/dev/null"])


def test_header_and_sources_compile_as_cxx(driver, tmp_path):
    exe = tmp_path / "driver_cxx"
    run(["g++", "-x", "c++", "-std=c++17", *STRICT, "-O0", f"-I{CDIR}", *SOURCES, str(driver), "-o", str(exe)])
    assert run([str(exe)]).stdout.strip() == "ok"


def test_kernels_clean_under_sanitizers(driver, tmp_path):
    exe = tmp_path / "driver_san"
    flags = ["-fsanitize=address,undefined", "-fno-sanitize-recover=all", "-fno-omit-frame-pointer", "-O0"]
    run(["gcc", "-std=c99", *STRICT, *flags, f"-I{CDIR}", *SOURCES, str(driver), "-o", str(exe), "-lm"])
    res = run([str(exe)], env={"ASAN_OPTIONS": "detect_leaks=1:abort_on_error=1", "UBSAN_OPTIONS": "halt_on_error=1"})
    assert res.stdout.strip() == "ok" and res.stderr == ""


def test_driver_detects_a_broken_kernel(driver, tmp_path):
    """The driver's check can fail: a kernel whose batch disagrees with its single call is caught."""
    broken = tmp_path / "broken.c"
    src = Path(SOURCES[0]).read_text()
    # make the first batch function skip its first item
    src = src.replace("for (k = 0; k < count; ++k) {", "for (k = 1; k < count; ++k) {", 1)
    broken.write_text(src)
    exe = tmp_path / "driver_broken"
    others = [s for s in SOURCES if s != SOURCES[0]]
    run(["gcc", "-std=c99", "-O0", f"-I{CDIR}", str(broken), *others, str(driver), "-o", str(exe), "-lm"])
    res = subprocess.run([str(exe)], capture_output=True, text=True)
    assert res.returncode != 0 and "item 0" in res.stdout
