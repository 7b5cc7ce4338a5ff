"""Text fields of a chain (its name and description; issue 36 item 1).

One rule for every text field: control characters (C0 including tab and newlines, DEL, C1), lone
surrogates and Unicode non-characters are refused where the text enters apair (a chain file, the
`_validate.text` check), with a one-line error naming the field and the code point. Whatever is
accepted is written so that each output format parses and carries the name intact where it can:
the viewer page (HTML and JSON in a script), the code of `apair codegen` (C comments, CMake,
Python), and a chain file read back.
"""

from __future__ import annotations

import json
import re
import subprocess
from html.parser import HTMLParser

import pytest

import apair
from apair import _validate as V
from apair import io, specialise, view

JOINT = '[[joint]]\npair = "revolute"\na = 0.1\nalpha = 0.0\n'

HOSTILE = [
    'double "quoted"',
    "single 'quoted'",
    "back\\slash \\n \\u0041 \\",
    "*/ /* ??/ ??= ??' trigraphs */",
    "</script><script>alert(1)</script>",
    "<!-- <script> -->",
    "]]> <![CDATA[ x ]]>",
    "& &amp; &#0; &lt;",
    "${HOME} @PROJECT_NAME@ $ENV{PATH} ; # [[x]]",
    "ünïcødé ☃ 中文 𝄞 ﷺ",
    "emoji 🤖 family 👨\u200d👩\u200d👧 rtl \u202e override",
    "line\u2028para\u2029sep",
    "APAIR_TITLE /*APAIR_CHAIN*/null",
    "  leading and trailing  ",
    " ",
    "",
]

# Refused in a chain file (written with TOML's escapes; tab raw, as TOML allows it)
REFUSED_IN_TOML = ["\x00", "bell\x07", "tab\t", "line\nfeed", "cr\r", "esc\x1b[0m", "del\x7f", "nel\x85", "c1\x9f"]
REFUSED_IN_TOML += ["non\ufffe", "char\uffff", "\ufdd0 block", "plane 1 \U0001fffe", "plane 16 \U0010ffff"]
REFUSED = REFUSED_IN_TOML + ["lone \ud800 surrogate", "\udfff"]  # no TOML string can hold these


def first_refused(text):
    """The first character the rule refuses, found independently of apair's own check."""
    for ch in text:
        cp = ord(ch)
        if cp < 0x20 or 0x7F <= cp <= 0x9F or 0xD800 <= cp <= 0xDFFF:
            return ch
        if 0xFDD0 <= cp <= 0xFDEF or cp & 0xFFFE == 0xFFFE:
            return ch
    return None


def toml_string(text):
    """A TOML basic string holding text: quotes, backslashes and control characters escaped."""
    out = []
    for ch in text:
        if ch in '"\\':
            out.append("\\" + ch)
        elif ord(ch) < 0x20 and ch != "\t" or ord(ch) == 0x7F:
            out.append(f"\\u{ord(ch):04X}")
        else:
            out.append(ch)
    return '"' + "".join(out) + '"'


def one_line(exc):
    msg = str(exc.value)
    assert "\n" not in msg and len(msg) < 300, msg
    return msg


# ----------------------------------------------------------------------------- refused on the way in
@pytest.mark.parametrize("name", REFUSED_IN_TOML)
def test_a_chain_file_whose_name_holds_a_refused_character_is_refused(tmp_path, name):
    bad = first_refused(name)
    path = tmp_path / "x.toml"
    path.write_text(f"name = {toml_string(name)}\n{JOINT}", encoding="utf-8")
    with pytest.raises(ValueError) as exc:
        io.load(path)
    msg = one_line(exc)
    assert msg.startswith(f"{path}: name: holds the ") and f"U+{ord(bad):04X}" in msg, msg
    assert f"character {name.index(bad) + 1}" in msg, msg
    assert not any(first_refused(c) for c in msg), msg  # the message itself is printable


@pytest.mark.parametrize("name", REFUSED_IN_TOML)
def test_loads_refuses_it_too_naming_its_label(name):
    with pytest.raises(ValueError, match=rf"^my chain: name: .*U\+{ord(first_refused(name)):04X}"):
        io.loads(f"name = {toml_string(name)}\n{JOINT}", where="my chain")


@pytest.mark.parametrize("text", [t for t in REFUSED_IN_TOML if t not in ("tab\t", "line\nfeed")])
def test_a_description_holds_lines_but_no_other_control(text):
    """A description may span lines (newlines, tabs): any other refused character is refused."""
    good = "first line\n\tsecond line, tab\n"
    chain = io.loads(f"description = {toml_string(good)}\n{JOINT}")
    assert chain.n == 1
    with pytest.raises(ValueError, match=rf"^chain: description: .*U\+{ord(first_refused(text)):04X}"):
        io.loads(f"description = {toml_string(good + text)}\n{JOINT}")


@pytest.mark.parametrize("key, value", [("name", "42"), ("name", "[1, 2]"), ("description", "true")])
def test_a_text_field_that_is_no_string_is_refused(key, value):
    with pytest.raises(ValueError, match=rf"^chain: {key}: expected a string, got "):
        io.loads(f"{key} = {value}\n{JOINT}")


@pytest.mark.parametrize("name", REFUSED)
def test_the_rule_refuses_each_character_naming_field_and_code_point(name):
    bad = first_refused(name)
    with pytest.raises(ValueError, match=rf"^chain\.name: holds the .*U\+{ord(bad):04X}") as exc:
        V.text("chain.name", name)
    one_line(exc)
    kind = "lone surrogate" if 0xD800 <= ord(bad) <= 0xDFFF else "non-character" if bad >= "\ufdd0" else "control"
    assert kind in str(exc.value)


@pytest.mark.parametrize("value", [b"bytes", None, 3, ["list"]])
def test_the_rule_refuses_what_is_no_string(value):
    with pytest.raises(ValueError, match=r"^title: expected a string, got "):
        V.text("title", value)


@pytest.mark.parametrize("name", HOSTILE)
def test_the_rule_accepts_every_other_text(name):
    assert V.text("name", name) == name


def test_a_file_name_with_a_refused_character_gives_a_usable_default_name(tmp_path):
    """The default name is the file's stem: one that holds a refused character is not refused
    (the file is fine), its characters are replaced, so that every writer takes the chain."""
    path = tmp_path / "bell\x07 chain.toml"
    path.write_text(JOINT)
    chain = io.load(path)
    assert chain.name == "bell\ufffd chain" and V.text("name", chain.name) == chain.name


@pytest.mark.parametrize("stem", ["line\nfeed", "bell\x07", "esc\x1b[31m"])
def test_errors_in_a_file_whose_name_holds_a_control_character_stay_one_printable_line(tmp_path, stem):
    path = tmp_path / f"{stem}.toml"
    path.write_text("[[joint]\n")
    with pytest.raises(ValueError) as exc:
        io.load(path)
    msg = one_line(exc)
    assert msg.isprintable() and msg.startswith(repr(str(path))) and "not valid TOML" in msg, msg


# ----------------------------------------------------------------------------- TOML: read back intact
@pytest.mark.parametrize("name", HOSTILE)
def test_hostile_names_round_trip_through_a_chain_file(tmp_path, name):
    path = tmp_path / "chain.toml"
    path.write_text(f"name = {toml_string(name)}\n{JOINT}", encoding="utf-8")
    assert io.load(path).name == name
    assert io.loads(f"name = {toml_string(name)}\n{JOINT}").name == name


# ----------------------------------------------------------------------------- the viewer page
class Page(HTMLParser):
    """The page's title, first h1 and scripts, as a browser's tokeniser splits them."""

    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.open, self.title, self.h1, self.scripts = None, "", [], []

    def handle_starttag(self, tag, attrs):
        self.open = tag
        if tag == "script":
            self.scripts.append("")
        elif tag == "h1":
            self.h1.append("")

    def handle_endtag(self, tag):
        self.open = None

    def handle_data(self, data):
        if self.open == "title":
            self.title += data
        elif self.open == "script":
            self.scripts[-1] += data
        elif self.open == "h1":
            self.h1[-1] += data


def r_chain(name):
    chain = apair.AChain([apair.APair.revolute()], [0.1], [0.0])
    chain.name = name
    return chain


@pytest.mark.parametrize("name", HOSTILE)
def test_hostile_names_in_the_viewer_page_parse_and_round_trip(name):
    html = view.to_html(r_chain(name))
    template = Page()
    template.feed(view.to_html(r_chain("plain")))
    page = Page()
    page.feed(html)
    page.close()
    shown = name or "apair chain"
    assert len(page.scripts) == len(template.scripts)  # no script closed early or opened
    assert page.title == f"{shown}: apair view" and page.h1[0] == shown
    script = next(s for s in page.scripts if "var chain = " in s)
    data, _ = json.JSONDecoder().raw_decode(script, script.index("var chain = ") + len("var chain = "))
    assert data["name"] == shown
    for s in page.scripts:  # what would end or change a script's data in a browser
        assert not re.search(r"</script|<!--|<script", s, re.IGNORECASE)
        assert "\u2028" not in s and "\u2029" not in s


@pytest.mark.parametrize("name", REFUSED)
def test_a_name_with_a_refused_character_is_refused_when_set(name):
    """chain.name is checked when it is set, so no writer (viewer, MJCF, C) ever meets it."""
    with pytest.raises(ValueError, match=rf"^name: holds the .*U\+{ord(first_refused(name)):04X}"):
        r_chain(name)


# ----------------------------------------------------------------------------- the generated code
@pytest.fixture(scope="module")
def lowered_fk():
    chain = r_chain("x")
    return chain, specialise.lowered(chain, ["fk"])


def compiles(folder, prefix):
    """gcc finds nothing to warn about in the generated C (trigraphs, nested comments included)."""
    for source in (f"{prefix}.c", f"{prefix}_selftest.c"):
        res = subprocess.run(
            ["gcc", "-std=c99", "-fsyntax-only", "-Wall", "-Wextra", "-Werror", "-Wtrigraphs", source],
            cwd=folder,
            capture_output=True,
            text=True,
        )
        assert res.returncode == 0, res.stderr


@pytest.mark.parametrize("name", HOSTILE)
def test_hostile_names_in_generated_code_compile_and_stay_ascii(tmp_path, lowered_fk, name):
    chain, code = lowered_fk
    files = specialise.render(chain, "hostile", f"{name}.toml", ["fk"], title=name, code=code)
    for rel, text in files.items():
        assert text.isascii(), (rel, [c for c in text if not c.isascii()][:5])
        (tmp_path / rel).write_text(text, encoding="ascii")
    compiles(tmp_path, "hostile")
    compile(files["hostile.py"], "hostile.py", "exec")
    assert json.loads(files["manifest.json"])["prefix"] == "hostile"
    header = files["hostile.h"].splitlines()[1]
    title = re.fullmatch(r" \* hostile\.h -- the kernels of the chain (.*), with its design built in\.", header)
    assert title and title.group(1).strip(), header  # a title, never an empty one


def test_plain_titles_are_written_as_they_are(lowered_fk):
    chain, code = lowered_fk
    name = "Arm 2 (left), v1.5: base-to-tool +z"
    files = specialise.render(chain, "plain", "arm.toml", ["fk"], title=name, code=code)
    assert f"the kernels of the chain {name}, with" in files["plain.h"]
    assert f'DESCRIPTION "Kinematics and dynamics of the chain {name} (generated' in files["CMakeLists.txt"]


def test_non_ascii_titles_keep_their_code_points(lowered_fk):
    """A letter outside ASCII is written as its code point, not dropped or passed to a compiler."""
    chain, code = lowered_fk
    files = specialise.render(chain, "uni", "arm.toml", ["fk"], title="Gelenk für 🤖", code=code)
    assert "Gelenk f<U+00FC>r <U+1F916>" in files["uni.h"]


@pytest.mark.parametrize("name", REFUSED)
def test_codegen_refuses_a_title_with_a_refused_character(lowered_fk, name):
    chain, code = lowered_fk
    with pytest.raises(ValueError, match=rf"^title: holds the .*U\+{ord(first_refused(name)):04X}"):
        specialise.render(chain, "bad", "bad.toml", ["fk"], title=name, code=code)


def test_cmake_configures_with_the_most_hostile_title(tmp_path, lowered_fk):
    """CMake reads the title in a comment and in a quoted string: every hostile name at once."""
    chain, code = lowered_fk
    title = " ".join(HOSTILE)
    files = specialise.render(chain, "hostile", "x.toml", ["fk"], title=title, code=code)
    src = tmp_path / "src"
    src.mkdir()
    for rel, text in files.items():
        (src / rel).write_text(text)
    res = subprocess.run(
        ["cmake", "-S", str(src), "-B", str(tmp_path / "build"), "-DBUILD_TESTING=OFF"],
        capture_output=True,
        text=True,
    )
    assert res.returncode == 0, res.stderr[-2000:]
