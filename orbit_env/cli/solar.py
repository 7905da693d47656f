"""``orbit-env solar``: the space-weather record NRLMSIS follows when an orbit has a date.

``orbit-env solar show`` says which record is in use and what it covers;
``orbit-env solar update FILE`` imports a newer CelesTrak space-weather file
(``SW-All.txt`` or ``SW-Last5Years.txt`` from https://celestrak.org/SpaceData/) that the user downloaded.
Nothing is downloaded here. See `orbit_env.decay.solar_record`.
"""

from __future__ import annotations

import argparse
from typing import Any


def _cmd_update(args: argparse.Namespace) -> int:
    from orbit_env.decay.solar import iso_date
    from orbit_env.decay.solar_record import update

    record, target = update(args.file)
    print(
        f"imported {args.file} (updated {record.updated}): observed to {iso_date(record.observed_end_days)}, "
        f"forecast to {iso_date(record.end_days)}; stored in {target}"
    )
    return 0


def _cmd_show(args: argparse.Namespace) -> int:
    from orbit_env.decay.solar_record import SHIPPED_RECORD, load_record, user_record_path

    record = load_record()
    user = user_record_path()
    where = f"imported, {user}" if user.is_file() else f"shipped, {SHIPPED_RECORD}"
    print(f"record             {record.describe()}")
    print(f"file               {where} (source updated {record.updated})")
    return 0


def add_parsers(sub: Any) -> None:
    """The ``solar`` command and its ``show`` and ``update`` subcommands."""
    solar = sub.add_parser("solar", help="the observed and forecast solar activity NRLMSIS follows (show, update)")
    actions = solar.add_subparsers(
        dest="solar_command", metavar="{show,update}", required=True, parser_class=type(solar)
    )
    show = actions.add_parser("show", help="which space-weather record is in use, and its dates")
    show.set_defaults(func=_cmd_show)
    update = actions.add_parser(
        "update", help="import a CelesTrak space-weather file you downloaded (SW-All.txt or SW-Last5Years.txt)"
    )
    update.add_argument(
        "file", metavar="FILE", help="CelesTrak's SW-All.txt or SW-Last5Years.txt (https://celestrak.org/SpaceData/)"
    )
    update.set_defaults(func=_cmd_update)
