"""The system programs that the tests drive: a Chromium for the viewer's browser test
(tests/exports/test_view.py) and clang for the C checks (tests/generation/test_c_hygiene.py).

`python tests/sysdeps.py browser` (`make browser`, part of `make test`) finds a Chromium, in this
order: `$CHROMIUM`, one on PATH (chromium, chromium-browser, google-chrome, ...), Playwright's own
(in `~/.cache/ms-playwright`). When there is none it installs Debian's package chromium with
apt-get as root or with a sudo that asks for no password, else Playwright's own build with
`python -m playwright install chromium` (no root: into the user's cache; it needs the network to
reach Playwright's downloads); when that fails too it stops and names the commands to run. The
browser test finds the browser the same way and fails, never skips, without one.

`python tests/sysdeps.py clang` (`make clang`, part of `make test`) installs Debian's clang and
libclang-rt-dev (the sanitizer runtimes) the same way when clang is missing; without root or sudo
it names the command and goes on: the clang configurations of the C checks are then skipped,
each saying which packages would run it.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import NamedTuple

# Debian's packages (apt-get install); the README and the skip messages name the same.
CHROMIUM_PACKAGES = ("chromium",)
CLANG_PACKAGES = ("clang", "libclang-rt-dev")
# a system's Chromium under the names distributions and Google give it, in this order
SYSTEM_BROWSERS = ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable", "chrome")
SANITIZE = ["-fsanitize=address,undefined", "-fno-sanitize-recover=all", "-fno-omit-frame-pointer"]


class Browser(NamedTuple):
    path: str
    origin: str  # "$CHROMIUM", "system" or "playwright"


class BrowserError(RuntimeError):
    """$CHROMIUM names no browser that runs."""


def apt_command(packages: tuple[str, ...]) -> str:
    return "apt-get install -y --no-install-recommends " + " ".join(packages)


def root_prefix() -> list[str] | None:
    """[] as root, ["sudo", "-n"] where sudo asks for no password, None otherwise (or without apt-get)."""
    if shutil.which("apt-get") is None:
        return None
    if os.geteuid() == 0:
        return []
    sudo = shutil.which("sudo")
    if sudo and subprocess.run([sudo, "-n", "true"], capture_output=True).returncode == 0:
        return [sudo, "-n"]
    return None


def apt_install(packages: tuple[str, ...]) -> bool:
    """Install Debian packages as root or with a password-less sudo; False where neither is possible
    or apt-get fails (its output is shown)."""
    prefix = root_prefix()
    if prefix is None:
        return False
    env = dict(os.environ, DEBIAN_FRONTEND="noninteractive")
    print(f"installing {' '.join(packages)} (Debian packages) with apt-get", flush=True)
    for args in (
        ["apt-get", "update", "-qq"],
        ["apt-get", "install", "-y", "-qq", "--no-install-recommends", *packages],
    ):
        if subprocess.run([*prefix, *args], env=env).returncode != 0:
            return False
    return True


def runs(path: str) -> bool:
    """Whether the browser at path starts (`--version`): a stub that names a missing snap does not."""
    try:
        return subprocess.run([path, "--version"], capture_output=True, timeout=60).returncode == 0
    except (OSError, subprocess.TimeoutExpired):
        return False


def playwright_executable() -> str | None:
    """Where Playwright keeps its own Chromium (installed there or not); None without Playwright.
    Asked in a process of its own: Playwright's sync API does not nest in a running one."""
    code = "from playwright.sync_api import sync_playwright\nwith sync_playwright() as p: print(p.chromium.executable_path)"
    try:
        res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    except (OSError, subprocess.TimeoutExpired):
        return None
    return (res.stdout.strip() or None) if res.returncode == 0 else None


def playwright_browser() -> str | None:
    """Playwright's own Chromium (python -m playwright install chromium), if it is installed."""
    path = playwright_executable()
    return path if path is not None and os.path.isfile(path) and os.access(path, os.X_OK) else None


def find_browser() -> Browser | None:
    """The Chromium the browser test drives: $CHROMIUM, else the system's, else Playwright's own;
    None when there is none. A $CHROMIUM that names no browser that runs is an error, not passed over."""
    chosen = os.environ.get("CHROMIUM")
    if chosen:
        path = shutil.which(chosen)
        if path is None or not runs(path):
            raise BrowserError(f"CHROMIUM={chosen} names no Chromium that runs: set it to one, or unset it")
        return Browser(path, "$CHROMIUM")
    for name in SYSTEM_BROWSERS:
        path = shutil.which(name)
        if path is not None and runs(path):
            return Browser(path, "system")
    path = playwright_browser()
    return Browser(path, "playwright") if path is not None else None


def missing_browser_message() -> str:
    python = sys.executable
    return (
        "no Chromium for the browser test (tests/exports/test_view.py): none in $CHROMIUM, none on PATH "
        f"({', '.join(SYSTEM_BROWSERS)}), and Playwright has none of its own. Install one, then run make test again:\n"
        f"  as root (Debian/Ubuntu):  {apt_command(CHROMIUM_PACKAGES)}\n"
        f"  or with sudo:             sudo {apt_command(CHROMIUM_PACKAGES)}\n"
        f"  without root (download):  {python} -m playwright install chromium\n"
        "  or name one you have:     export CHROMIUM=/path/to/chromium-or-chrome"
    )


def playwright_install() -> bool:
    """Playwright's own Chromium into the user's cache (no root; it downloads from Playwright's site)."""
    print(f"installing Playwright's Chromium: {sys.executable} -m playwright install chromium", flush=True)
    return subprocess.run([sys.executable, "-m", "playwright", "install", "chromium"]).returncode == 0


def ensure_browser() -> int:
    """Find a Chromium, or install one (Debian's package where root or sudo allows, else
    Playwright's); 0 when there is one, else 1 with the commands to run."""
    try:
        found = find_browser()
        if found is None and apt_install(CHROMIUM_PACKAGES):
            found = find_browser()
        if found is None and playwright_install():
            found = find_browser()
    except BrowserError as e:
        print(f"error: {e}", file=sys.stderr)
        return 1
    if found is None:
        print(f"error: {missing_browser_message()}", file=sys.stderr)
        return 1
    print(f"browser test: Chromium {found.path} ({found.origin})")
    return 0


def clang_missing(workdir: Path | None = None) -> str | None:
    """Why the clang configurations of the C checks cannot run here (naming the packages), or None."""
    missing = [c for c in ("clang", "clang++") if shutil.which(c) is None]
    if missing:
        return f"{' and '.join(missing)} not installed"
    with tempfile.TemporaryDirectory(dir=workdir) as tmp:
        src = Path(tmp) / "probe.c"
        src.write_text("int main(void) { return 0; }\n")
        res = subprocess.run(["clang", *SANITIZE, str(src), "-o", str(Path(tmp) / "probe")], capture_output=True)
    return None if res.returncode == 0 else "clang has no sanitizer runtime"


def clang_skip_reason(why: str) -> str:
    return f"{why}: `make clang` installs it as root or with sudo (Debian/Ubuntu: {apt_command(CLANG_PACKAGES)})"


def ensure_clang() -> int:
    """Install clang where root or sudo allows; without, say so and go on (the checks then skip)."""
    why = clang_missing()
    if why is not None and apt_install(CLANG_PACKAGES):
        why = clang_missing()
    if why is None:
        print(f"C checks: clang {shutil.which('clang')} (with ASan and UBSan)")
    else:
        print(f"note: {clang_skip_reason(why)}; the C checks' clang configurations will be skipped", file=sys.stderr)
    return 0


def main(argv: list[str]) -> int:
    if argv == ["browser"]:
        return ensure_browser()
    if argv == ["clang"]:
        return ensure_clang()
    print("usage: python tests/sysdeps.py browser|clang", file=sys.stderr)
    return 2


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
