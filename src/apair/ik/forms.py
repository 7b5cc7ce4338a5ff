"""Which closed form solves a six-joint chain (issue 42): its family's (apair.ik.wrist,
apair.ik.parallel, apair.ik.three_parallel; apair.ik.parallel_apair for a UR-like arm with an A-pair
at joint 3, apair.ik.parallel_slides for one with A-pairs at joints 1 and 5, apair.ik.wrist_apair
and wrist_slide1 for a spherical-wrist arm with an A-pair at joint 3 or 1), at the tool end or, for
an R-chain's family at the base end, the reversed chain's (apair.ik.reverse); None where the chain
has none (the general solvers answer)."""

from __future__ import annotations

from . import parallel, parallel_apair, parallel_slides, three_parallel, wrist, wrist_apair, wrist_slide1
from .families import Classification, classify
from .reverse import Reversed, ReversedView

Forward = (
    wrist.Wrist
    | parallel.Parallel
    | three_parallel.ThreeParallel
    | parallel_apair.ParallelAPair
    | parallel_slides.ParallelSlides
    | wrist_apair.WristAPair
    | wrist_slide1.WristSlide1
)
Form = Forward | Reversed


def forward_form(chain, family: Classification, scale: float) -> Forward | None:
    """The closed-form solver of a chain's forward family (`family`: classify(chain))."""
    if wrist.applies(chain, family):
        return wrist.Wrist(chain, scale)
    for module, make in (
        (parallel, parallel.Parallel),
        (three_parallel, three_parallel.ThreeParallel),
        (parallel_apair, parallel_apair.ParallelAPair),
        (parallel_slides, parallel_slides.ParallelSlides),
        (wrist_apair, wrist_apair.WristAPair),
        (wrist_slide1, wrist_slide1.WristSlide1),
    ):
        if module.applies(chain, family):
            try:
                return make(chain, scale)
            except ValueError:  # a design the form does not cover (axes 5 and 6 one line, not UR's wrist, ...)
                return None
    return None


def closed_form(chain, family: Classification, scale: float) -> Form | None:
    """The closed-form solver of the chain's family (`family`: classify(chain)), forward or at the
    base end, if it has one."""
    form = forward_form(chain, family, scale)
    f = family.family
    if form is not None or f is None or not f.reversed or any(p.kind != "revolute" for p in chain.pairs):
        return form
    view = ReversedView(chain)
    inner = forward_form(view, classify(view), scale)
    return None if inner is None else Reversed(chain, scale, view, inner)
