"""The ``orbit-env`` command line.

Lifetimes (one orbit or a CSV batch), disposal rules, density fits, Table II, Fig. 2,
training and evaluating agents.
One module per group of commands (`lifetime`, `paper`,
`agents`), sharing `common`. Every error a user can
cause ends in one line on stderr and exit status 2, in the command line's words.
"""

from __future__ import annotations

import functools
import os
import signal
import sys
import threading
import warnings
from collections.abc import Callable, Sequence
from typing import Any

from orbit_env import cache
from orbit_env.checks import InputError
from orbit_env.cli import agents, lifetime, paper, solar
from orbit_env.cli.common import FLAGS, PROG, Parser, in_files, in_flags

__all__ = ["FLAGS", "PROG", "build_parser", "main"]


def build_parser() -> Parser:
    """The full ``orbit-env`` parser."""
    parser = Parser(prog=PROG, description="Satellite decay by Okhotsimsky, Eneev and Taratynova (1957).")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=Parser)
    lifetime.add_parsers(sub)
    paper.add_parsers(sub)
    agents.add_parsers(sub)
    solar.add_parsers(sub)
    for command in sub.choices.values():
        command.add_argument(
            "--no-cache",
            action="store_true",
            help=f"neither read nor write the disk cache of curves and profiles ({cache.ENV_VAR}=off does the same)",
        )
    return parser


def _show_warning(default: Callable[..., None], message: Any, category: type[Warning], *rest: Any, **kw: Any) -> None:
    """An unwritable cache in one line, as the command's other warnings; other warnings as Python shows them."""
    if issubclass(category, cache.CacheWarning):
        print(f"{PROG}: warning: {message}", file=sys.stderr)
    else:
        default(message, category, *rest, **kw)


def _interrupt(signum: int, frame: Any) -> None:
    """SIGTERM as Ctrl-C (see `main`)."""
    raise KeyboardInterrupt


def _default_in_child() -> None:
    """A forked child dies of SIGTERM at once, as before.

    A pool stops its workers so, and a Python handler would wait for the NRLMSIS call under way to return.
    """
    if signal.getsignal(signal.SIGTERM) is _interrupt:
        signal.signal(signal.SIGTERM, signal.SIG_DFL)


os.register_at_fork(after_in_child=_default_in_child)


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; return the exit status."""
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.no_cache:
        cache.disable()
        os.environ[cache.ENV_VAR] = "off"  # and in the worker processes a batch starts
    # SIGTERM (a session's end, ``kill``) stops a command as Ctrl-C does: workers stopped, parts and a
    # training's checkpoint kept. Only in the main thread, where signal handlers live, and not over a handler
    # set outside Python (which could not be put back); restored after.
    ours = threading.current_thread() is threading.main_thread() and signal.getsignal(signal.SIGTERM) is not None
    before = signal.signal(signal.SIGTERM, _interrupt) if ours else None
    shown = warnings.showwarning
    warnings.showwarning = functools.partial(_show_warning, shown)
    try:
        return int(args.func(args))
    except (ValueError, ImportError, OSError) as error:
        text = in_flags(error, args) if isinstance(error, InputError) else in_files(error, args)
        message = text.splitlines()[0] if text else type(error).__name__
        print(f"{PROG}: error: {message}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:  # Ctrl-C: one line, the shell's status for it (a batch keeps its parts itself)
        print(f"{PROG}: interrupted", file=sys.stderr)
        return 130
    finally:
        warnings.showwarning = shown
        if ours:
            signal.signal(signal.SIGTERM, before)
