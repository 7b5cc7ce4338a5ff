"""The parser of `apair` and `main`, the one place where a command's failure becomes its one-line
message and exit status."""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Sequence

from .._version import __version__
from . import compare, design, exports, importer, info, motion, reach
from .args import NEGATIVE_NUMBER
from .output import one_line

# the commands in the order of `apair --help`
COMMANDS = (
    info.add_list,
    info.add_show,
    motion.add_fk,
    motion.add_jacobian,
    motion.add_dynamics,
    info.add_variety,
    reach.add_ik,
    reach.add_ik_prepare,
    motion.add_limits,
    reach.add_workspace,
    compare.add_compare,
    design.add_design,
    exports.add_codegen,
    exports.add_export,
    importer.add_import,
    exports.add_view,
    info.add_kernels,
    info.add_demo,
)


class _Parser(argparse.ArgumentParser):
    """argparse's parser that takes every negative number as a value, exponent form included
    (`-1e-3`, `-2.5E+4`, `-inf`), and lists that start with one (`--q -0.1,0.2`): the standard
    one reads those as unknown options."""

    def __init__(self, *args: object, **kwargs: object) -> None:
        super().__init__(*args, **kwargs)  # type: ignore[arg-type]
        self._negative_number_matcher = NEGATIVE_NUMBER


def build_parser() -> argparse.ArgumentParser:
    ap = _Parser(prog="apair", description="Kinematics of A-pairs and A-chains.")
    ap.add_argument("--version", action="version", version=f"apair {__version__}")
    sub = ap.add_subparsers(dest="command", required=True)
    for add in COMMANDS:
        add(sub)
    return ap


def main(argv: Sequence[str] | None = None) -> int:
    """Run one command; every failure ends in a one-line message and a non-zero exit, never a
    traceback: 2 for bad input, 1 for an unreachable pose, 141 when the reader of the output went
    away (`apair kernels | head`), 130 on Ctrl-C, 3 for an internal error."""
    ap = build_parser()
    args = ap.parse_args(argv)
    try:
        code: int = args.func(args)
        sys.stdout.flush()
        return code
    except BrokenPipeError:
        # the reader closed the pipe: stop quietly, and keep Python from complaining at exit
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 141
    except KeyboardInterrupt:
        print(f"apair {args.command}: interrupted", file=sys.stderr)
        return 130
    except (ValueError, OSError) as exc:
        print(f"apair {args.command}: error: {one_line(exc)}", file=sys.stderr)
        return 2
    except Exception as exc:
        print(
            f"apair {args.command}: internal error: {type(exc).__name__}: {one_line(exc)} "
            "(please report this with the command line)",
            file=sys.stderr,
        )
        return 3
