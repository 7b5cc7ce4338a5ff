"""The JavaScript backend: the kernels the browser viewer (apair view) evaluates, in
js/apair_kernels.js: the pair laws, one joint's transform (the page multiplies them into every
frame) and the leg end points."""

from __future__ import annotations

from pathlib import Path

from ...hashing import content_hash
from ...ir import Lowered
from ...templating import Templates, TemplateSource

TEMPLATES = Templates(Path(__file__).parent / "templates")
WEB_KERNELS = (
    "law_revolute",
    "law_sinusoidal",
    "law_general",
    "law_helical",
    "law_prismatic",
    "fk1",
    "pair_legs",
)  # lowered with JavaScript too


def render(kernels: list[Lowered], template: TemplateSource = TEMPLATES) -> dict[str, str]:
    """{path under generated/: text}: the viewer's kernels, if `kernels` has them all (not all
    derivations run with `python -m codegen --only`), else nothing."""
    web = sorted((k for k in kernels if k.js is not None), key=lambda k: k.name)
    if sorted(k.name for k in web) != sorted(WEB_KERNELS):
        return {}
    t, src = template("kernels.js.j2")
    return {
        "js/apair_kernels.js": t.render(
            kernels=web,
            sources=sorted({k.spec.source for k in web}),
            hash=content_hash([src] + [k.fingerprint for k in web]),
        )
    }
