"""What every ``orbit-env`` command shares: one-line errors, numbers that remember how they were typed, flags.

An error in a value names the flag and the value as typed (``--perigee 50 is out of
range; allowed: 100 to 50000 km``): the API raises `orbit_env.checks.InputError`
naming its parameter, and `FLAGS` maps the parameter to the flag at one place.
"""

from __future__ import annotations

import argparse
import csv
import math
import os
import tempfile
from collections.abc import Sequence
from pathlib import Path
from typing import Any, NoReturn

from orbit_env.checks import InputError

PROG = "orbit-env"


class Parser(argparse.ArgumentParser):
    """An argument parser whose errors are one line."""

    def error(self, message: str) -> NoReturn:
        """Exit with status 2 and the message on one line."""
        self.exit(2, f"{self.prog}: error: {message} (see --help)\n")

    def _get_values(self, action: argparse.Action, arg_strings: list[str]) -> Any:
        # argparse drops a value "--" ("--apogee=--") and stores an empty list as the flag's value.
        if action.nargs is None and action.option_strings and arg_strings == ["--"]:
            self.error(f"argument {'/'.join(action.option_strings)}: expected one argument, got '--'")
        return super()._get_values(action, arg_strings)


def check_finite(values: dict[str, Any], what: str) -> None:
    """Refuse to output a NaN or an infinity: an error names the value, rather than a file or line holding it.

    Raises:
        ValueError: a float in ``values`` is not finite (a defect: the inputs were checked).
    """
    for key, value in values.items():
        for number in value if isinstance(value, (list, tuple)) else [value]:
            if isinstance(number, float) and not math.isfinite(number):
                raise ValueError(f"{what}: {key} came out as {number}; nothing written (a defect: please report it)")


def write_csv(path: str, rows: list[dict[str, Any]]) -> None:
    """Write rows of equal keys to a CSV file with a header, LF line endings; never a NaN or an infinity."""
    for row in rows:
        check_finite(row, path)
    with open(path, "w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=list(rows[0]), lineterminator="\n")
        writer.writeheader()
        writer.writerows(rows)


def check_output(
    path: str, option: str, inputs: Sequence[tuple[str, str | None]] = (), *, force: bool | None = None
) -> None:
    """Refuse, before any computing, an output file that would replace an input, or cannot be written.

    Args:
        path: The file to write.
        option: Its flag (``--out``), for the message.
        inputs: (what, path) of the other files the command reads or writes, ``what`` as the message says it
            (``"the input file of --tle"``); a path of None or ``-`` (stdin) is skipped.
        force: None: an existing file is replaced (``--trajectory``, ``--plot``, as ``-o`` of most tools
            does); False: an existing file is an error that names ``--force`` (a batch's ``--out``, whose
            results are costly); True: replaced.

    Raises:
        ValueError: ``path`` is an input (also through a link), a directory, exists where ``force`` is
            False, or its folder is missing or not writable.
    """
    out = Path(path)
    for what, source in inputs:
        if source in (None, "-"):
            continue
        same = out.exists() and Path(source).exists() and os.path.samefile(out, source)
        if same or out.resolve() == Path(source).resolve():
            raise ValueError(f"{option} {path} is {what}; write to another file")
    if out.is_dir():
        raise ValueError(f"{option} {path} is a directory; give a file name")
    if out.exists() and force is False:
        raise ValueError(f"{option} {path} exists; give --force to replace it, or another file name")
    folder = out.parent
    if not folder.is_dir():
        raise ValueError(f"{option} {path}: the folder {folder} does not exist")
    try:
        with tempfile.TemporaryFile(dir=folder):
            pass
    except OSError as error:
        raise ValueError(f"{option} {path}: cannot write in {folder} ({error.strerror or error})") from None


def check_figure(path: str, option: str, inputs: Sequence[tuple[str, str | None]] = ()) -> None:
    """`check_output` of a figure, and its name's extension a format matplotlib writes (the format is the name's).

    Raises:
        ValueError: as `check_output`, or no extension, or one matplotlib does not write.
    """
    check_output(path, option, inputs)
    try:
        from matplotlib.backend_bases import FigureCanvasBase
    except ImportError as error:  # as orbit_env.optional.pyplot says it, before any computing
        raise ImportError(f"{option} needs matplotlib: pip install 'orbit-env[plot]'") from error

    formats = sorted(FigureCanvasBase.get_supported_filetypes())
    if "pgf" in formats:  # matplotlib writes PGF through a LaTeX it runs: offered where there is one
        import shutil

        from matplotlib import rcParams

        if shutil.which(rcParams["pgf.texsystem"]) is None:
            formats.remove("pgf")
    suffix = Path(path).suffix.lower().lstrip(".")
    if suffix not in formats:
        raise ValueError(
            f"{option} {path}: the file name's extension gives the figure's format; allowed: "
            f"{', '.join('.' + f for f in formats)}"
        )


def given(args: argparse.Namespace, name: str) -> bool:
    """Whether the flag ``name`` was given on the command line."""
    value = getattr(args, name)
    return value is not None and value is not False


def flag(name: str) -> str:
    """The flag of an argparse dest: ``scale_height_km`` -> ``--scale-height-km``."""
    return "--" + name.replace("_", "-")


class Typed(float):
    """A number from the command line that remembers how it was typed (for messages)."""

    text: str


def number(text: str) -> float:
    """The argparse type of number flags: a float that remembers its text."""
    value = Typed(text)
    value.text = text.strip()
    return value


number.__name__ = "number"  # argparse says "invalid number value: 'abc'"

#: The API's parameter names (as `InputError` gives them) -> the flag's
#: argparse dest and, for a flag in other units than the parameter, the factor to the flag's unit and
#: that unit. ``scale`` is an atmosphere's, ``phase`` `CycleActivity.with_phase`'s.
FLAGS: dict[str, tuple[str, float, str | None]] = {
    "perigee_km": ("perigee", 1.0, None),
    "apogee_km": ("apogee", 1.0, None),
    "drag_coefficient": ("cx", 1.0, None),
    "mass_kg": ("mass", 1.0, None),
    "area_m2": ("area", 1.0, None),
    "mass_per_area_kg_m2": ("mass_per_area", 1.0, None),
    "rho100_kg_m3": ("rho100", 1.0, None),
    "density_scale": ("density_scale", 1.0, None),
    "scale": ("density_scale", 1.0, None),
    "rho0_kg_m3": ("rho0", 1.0, None),
    "h0_m": ("h0_km", 1e-3, "km"),
    "scale_height_m": ("scale_height_km", 1e-3, "km"),
    "f107_sfu": ("f107", 1.0, None),
    "f107a_sfu": ("f107a", 1.0, None),
    "ap": ("ap", 1.0, None),
    "phase": ("cycle_phase", 1.0, None),
    "ascending_node_local_time_h": ("node_local_time", 1.0, None),
    "chunk_days": ("chunk_days", 1.0, None),
    "inclination_deg": ("inclination", 1.0, None),
    "semi_major_axis_km": ("semi_major_axis_km", 1.0, None),
    "eccentricity": ("eccentricity", 1.0, None),
    "diameter_m": ("diameter_m", 1.0, None),
    "length_m": ("length_m", 1.0, None),
    "size_m": ("size_m", 1.0, None),
    "samples": ("samples", 1.0, None),
    "seed": ("seed", 1.0, None),
    "rule_years": ("rule", 1.0, None),
    "reentry_sigma_days": ("reentry_sigma_days", 1.0, None),
    "height_sigma_km": ("height_sigma_km", 1.0, None),
}


def in_flags(error: InputError, args: argparse.Namespace) -> str:
    """The error in the command line's words: the flag, the value as typed, the flag's unit."""
    if error.name == "mass_kg / area_m2" and error.index is None and given(args, "mass"):
        if given(args, "area"):
            return error.message("--mass / --area")  # G/F of the two flags, in their units
        if getattr(args, "shape", None) is not None:
            return error.message(f"--mass / the {args.shape}'s area")
    if error.name not in FLAGS or error.index is not None or not hasattr(args, FLAGS[error.name][0]):
        return str(error)  # not a flag's value (a file's cell, an element of a table)
    dest, factor, unit = FLAGS[error.name]
    typed = getattr(args, dest)
    return error.message(
        flag(dest),
        value_text=typed.text if isinstance(typed, Typed) else None,
        scale=factor,
        unit=unit,
        rename=lambda name: flag(FLAGS[name][0]) if name in FLAGS else name,
        shift=_height_shift_km(error, args, typed),
    )


def _height_shift_km(error: InputError, args: argparse.Namespace, typed: Any) -> float:
    """What turns a height checked above the 6371 km sphere into the user's --height-reference (0 otherwise).

    The decay checks the sphere's heights; a user who typed heights above the equatorial radius reads
    the bounds in those (the error's value is then the typed one plus the reference's offset).
    """
    from orbit_env.analysis.heights import HEIGHT_REFERENCES, offset_km

    reference = getattr(args, "height_reference", None)
    if error.name not in ("perigee_km", "apogee_km") or reference not in HEIGHT_REFERENCES:
        return 0.0
    offset = offset_km(reference)
    try:
        shown = float(error.value) * FLAGS[error.name][1]  # in the flag's unit (km)
        checked_sphere = math.isclose(shown, float(typed) + offset, rel_tol=0.0, abs_tol=1e-6)
    except (TypeError, ValueError):
        return 0.0
    return -offset if offset and checked_sphere else 0.0


#: The commands' positional arguments that name files (fit-density's OBS_CSV, solar update's FILE).
POSITIONALS = ("observations", "file")


def in_files(error: Exception, args: object) -> str:
    """An error's text; a file that cannot be read or written named with its flag (``--tle x.tle: ...``)."""
    if not (isinstance(error, OSError) and error.filename and error.strerror):
        return str(error)
    name = next((key for key, value in vars(args).items() if isinstance(value, str) and value == error.filename), None)
    where = f"{flag(name)} " if name and name not in POSITIONALS else ""  # a positional argument has no flag
    return f"{where}{error.filename}: {error.strerror.lower()}"


def output_file(text: str) -> str:
    """The argparse type of a file to write: a name, not an empty one nor ``-`` (no output goes to stdout)."""
    if not text.strip():
        raise argparse.ArgumentTypeError("an empty file name; give one")
    if text.strip() == "-":
        raise argparse.ArgumentTypeError("'-' (standard output) is not written to; give a file name")
    return text


output_file.__name__ = "file name"  # argparse says "invalid file name value: ..." if it ever falls through


def output_folder(text: str) -> str:
    """The argparse type of an output folder: not empty (an empty path is the current folder, never meant)."""
    if not text.strip():
        raise argparse.ArgumentTypeError("an empty path; give a folder")
    return text


def positive_int(text: str) -> int:
    """The argparse type of counts: an integer >= 1."""
    value = int(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be a positive integer, got {text}")
    return value
