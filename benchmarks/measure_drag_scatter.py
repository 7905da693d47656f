"""How uncertain is a drag parameter calibrated from one element set? Its scatter between nearby sets of one object.

For every object of benchmarks/data/reentry_tles with several sets in the usable window
(7 days to 3 years before re-entry), the drag parameter is calibrated from each set
(`orbit_env.analysis.drag_calibration.calibrate`, B* and ndot) in the default air (NRLMSIS
2.1 under the shipped record, co-rotating); for consecutive sets 1 to 15 days apart the
difference of ln c is taken. If each set's error is independent with sigma s, the
difference has sigma s sqrt(2): s = std / sqrt(2) (with the 1.4826 MAD estimate beside it,
robust to the odd outlier). This uses no re-entry outcome, so the band it sets can be
checked against the re-entries without circularity.

    python benchmarks/measure_drag_scatter.py [--max-sets 40]
"""

import argparse
import csv
import itertools
import math
from pathlib import Path

import numpy as np

from orbit_env.analysis.air import MsisAir
from orbit_env.analysis.drag_calibration import SOURCE_BSTAR_CALIBRATED, SOURCE_NDOT_CALIBRATED, calibrate
from orbit_env.analysis.elements import read_tle
from orbit_env.analysis.scenario import Scenario
from orbit_env.constants import DAYS_PER_YEAR
from orbit_env.decay.solar import unix_days
from orbit_env.decay.solar_record import load_record

DATA = Path(__file__).resolve().parent / "data" / "reentry_tles"


def objects():
    with open(DATA / "objects.csv") as handle:
        for row in csv.DictReader(handle):
            files = sorted(DATA.glob(f"{row['norad']}_*.tle"))
            if files and "flagged" not in row["notes"].lower():
                yield row, files[0]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--max-sets", type=int, default=40, help="sets per object, evenly spread (default 40)")
    args = parser.parse_args()
    record = load_record()
    diffs = {SOURCE_BSTAR_CALIBRATED: [], SOURCE_NDOT_CALIBRATED: []}
    for row, path in objects():
        reentry = unix_days(row["reentry_utc"].rstrip("Z")[:10])
        sets = [s for s in read_tle(path) if 7.0 <= reentry - s.epoch_days <= 3 * DAYS_PER_YEAR]
        if len(sets) < 2:
            continue
        keep = np.unique(np.linspace(0, len(sets) - 1, min(len(sets), args.max_sets)).round().astype(int))
        sets = [sets[i] for i in keep]
        for source in diffs:
            values = []
            for s in sets:
                scenario = Scenario(MsisAir(record, s.epoch_days))
                result = calibrate(s, scenario, source=source)
                values.append((s.epoch_days, None if result is None else result.drag_parameter_m2_kg))
            for (t0, c0), (t1, c1) in itertools.pairwise(values):
                if c0 and c1 and 1.0 <= t1 - t0 <= 15.0:
                    diffs[source].append(math.log(c1 / c0))
        print(f"{row['norad']:>6} {row['name'][:24]:24} {len(sets):3} sets", flush=True)
    for source, values in diffs.items():
        d = np.array(values)
        sd = float(np.std(d)) / math.sqrt(2.0)
        mad = 1.4826 * float(np.median(np.abs(d - np.median(d)))) / math.sqrt(2.0)
        print(f"{source}: {d.size} pairs 1-15 days apart, sigma of one set {sd:.3f} (MAD estimate {mad:.3f})")


if __name__ == "__main__":
    main()
