"""apair: closed-form kinematics of algebraic screw pairs (A-pairs) and A-chains.

The closed forms are derived symbolically (derivations/), emitted as C and NumPy kernels
(codegen/ -> generated/), and loaded here. See docs/conventions.md for frames and conventions.
"""

from . import plots, polynomials  # plots imports matplotlib only when a picture is drawn
from ._version import __version__
from .chain import AChain
from .frames import frame
from .io import load
from .kernels import backend, c_available, set_backend
from .link import Link
from .pair import APair
from .simulate import Trajectory
from .urdf import load_urdf

__all__ = [
    "APair",
    "AChain",
    "Link",
    "Trajectory",
    "frame",
    "load",
    "load_urdf",
    "plots",
    "polynomials",
    "set_backend",
    "backend",
    "c_available",
    "__version__",
]
