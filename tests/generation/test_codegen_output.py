"""`apair codegen --out DIR` never loses a file it does not own (issue: files a user owns).

Real files, real symbolic links, a crafted manifest and real concurrent processes, in a temporary
folder: a user's own file is refused unless --force, a link is never written through, a manifest's
entries outside DIR are never deleted, a stale file the user edited is kept, and two runs into one
new folder take turns.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from apair.cli import main as cli

EXAMPLE = str(Path(__file__).resolve().parents[2] / "examples" / "2a_chain.toml")


def codegen(out: Path, prefix: str, *extra: str) -> int:
    return cli(["codegen", EXAMPLE, "--prefix", prefix, "--kernels", "fk", "--out", str(out), *extra])


def one_line_error(capsys, *words: str) -> str:
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "Traceback" not in err, err
    for w in words:
        assert w in err, err
    return err


def test_a_users_own_file_is_refused_unless_force(tmp_path, capsys):
    out = tmp_path / "code"
    assert codegen(out, "one") == 0
    mine = out / "two.h"
    mine.write_text("/* my own header */\n")
    capsys.readouterr()
    assert codegen(out, "two") != 0
    one_line_error(capsys, "two.h", "--force")
    assert mine.read_text() == "/* my own header */\n"
    assert not (out / "two.c").exists()  # refused before anything was written
    assert codegen(out, "two", "--force") == 0
    assert "my own header" not in mine.read_text()


def test_a_link_is_never_written_through(tmp_path, capsys):
    out = tmp_path / "code"
    outside = tmp_path / "outside.c"
    outside.write_text("precious\n")
    assert codegen(out, "one") == 0
    # a link at a name an earlier run wrote: replaced by a file, its target untouched
    (out / "one.c").unlink()
    (out / "one.c").symlink_to(outside)
    assert codegen(out, "one") == 0
    assert not (out / "one.c").is_symlink() and "one_fk" in (out / "one.c").read_text()
    assert outside.read_text() == "precious\n"
    # a link at a name that is not ours: refused, and with --force the link itself is replaced
    (out / "two.c").symlink_to(outside)
    capsys.readouterr()
    assert codegen(out, "two") != 0
    one_line_error(capsys, "two.c", "symbolic link")
    assert codegen(out, "two", "--force") == 0
    assert not (out / "two.c").is_symlink()
    assert outside.read_text() == "precious\n"


def test_a_linked_subfolder_is_refused(tmp_path):
    from apair.codegen.output import OutputError, write

    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    out = tmp_path / "out"
    out.mkdir()
    (out / "sub").symlink_to(elsewhere)
    with pytest.raises(OutputError, match="symbolic link"):
        write(
            {"sub/x.c": "int x;\n", "manifest.json": json.dumps({"kernels": {}, "content_hash": "0"})}, out, force=True
        )
    assert not (elsewhere / "x.c").exists()


def test_a_crafted_manifest_deletes_nothing_outside(tmp_path):
    out = tmp_path / "code"
    assert codegen(out, "one") == 0
    victim = tmp_path / "victim.txt"
    victim.write_text("keep me\n")
    absolute = tmp_path / "absolute.txt"
    absolute.write_text("keep me too\n")
    manifest = json.loads((out / "manifest.json").read_text())
    manifest["files"] = dict(
        manifest["files"], **{"../victim.txt": None, str(absolute): None, "./one.c": None, "a/../../victim.txt": None}
    )
    (out / "manifest.json").write_text(json.dumps(manifest))
    assert codegen(out, "other") == 0  # the files of "one" are stale now
    assert victim.read_text() == "keep me\n" and absolute.read_text() == "keep me too\n"
    assert not (out / "one.h").exists()  # a stale file of ours, unchanged: removed


def test_a_stale_file_the_user_edited_is_kept(tmp_path, capsys):
    out = tmp_path / "code"
    assert codegen(out, "one") == 0
    (out / "one.c").write_text("/* edited by hand */\n")
    capsys.readouterr()
    assert codegen(out, "two") == 0
    assert (out / "one.c").read_text() == "/* edited by hand */\n"
    assert not (out / "one.h").exists()
    assert "kept one.c" in capsys.readouterr().out


def test_the_manifest_records_what_was_written(tmp_path):
    import hashlib

    out = tmp_path / "code"
    assert codegen(out, "one") == 0
    files = json.loads((out / "manifest.json").read_text())["files"]
    assert set(files) == {p.name for p in out.iterdir()} - {"manifest.json"}
    for name, sha in files.items():
        assert hashlib.sha256((out / name).read_bytes()).hexdigest() == sha


RACE = """
import sys
from apair.cli import main
sys.exit(main(["codegen", sys.argv[1], "--prefix", sys.argv[2], "--kernels", "fk", "--out", sys.argv[3]]))
"""


@pytest.mark.parametrize("prefixes", [("one", "one"), ("one", "two")])
def test_concurrent_runs_into_one_new_folder_take_turns(tmp_path, prefixes):
    for attempt in range(3):
        out = tmp_path / f"code{attempt}"
        procs = [
            subprocess.Popen(
                [sys.executable, "-c", RACE, EXAMPLE, p, str(out)],
                stdout=subprocess.PIPE,
                stderr=subprocess.PIPE,
                text=True,
            )
            for p in prefixes
        ]
        results = [p.communicate(timeout=300) + (p.returncode,) for p in procs]
        for _stdout, stderr, rc in results:
            assert rc == 0, stderr
        files = json.loads((out / "manifest.json").read_text())["files"]
        last = files and next(iter(files))
        assert last
        for name in files:
            assert (out / name).is_file(), f"{name} recorded but missing after two concurrent runs"
        assert not [p.name for p in out.iterdir() if p.name.endswith(".tmp")]
