"""Fuzzing that stays: random command lines and files through the CLI, random missions through the vector env.

The CLI's contract, checked on every case:

* exit 0: the output is finite and plausible (JSON numbers finite and consistent with
  each other and with Kepler's periods; result files complete, LF, no NaN; no warnings
  on stderr but the CLI's own ``orbit-env: warning:`` lines);
* any other exit: exactly one line on stderr, ``orbit-env: ...``, no traceback; for
  exit 2 nothing on stdout and no results file written. (Batch exit 1: the results
  file is complete and some rows have no lifetime, as docs/how-to/catalogue.md says.)

The default run tries 240 cases (lifetime 100, fit-density 70, batch 70) in about 25 s (measured on 2 shared cores);
``-m slow`` runs 11 000 (5000, 3000, 3000) and the env fuzz (10^5 episodes). NRLMSIS is
left out: each new inclination or activity builds a profile (seconds), too slow to fuzz.
"""

from __future__ import annotations

import contextlib
import csv
import io
import json
import math
import re
import warnings
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, settings
from hypothesis import given as given_
from hypothesis import strategies as st

from orbit_env.cli import main

MU = 3.986e14  # m^3/s^2, as the package
#: Radii bracketing every height reference of the package (the paper's 6371 km sphere, WGS84's
#: 6378.137 km equator, 6356.752 km pole): Kepler periods computed with them bracket the truth.
R_LOW_M, R_HIGH_M = 6356.0e3, 6378.2e3
NOT_FINITE = re.compile(r"\b(nan|inf|infinity)\b", re.IGNORECASE)
#: Words of Python's and numpy's own messages, which a user's error must not show.
INTERNAL = (
    "could not convert",
    "codec can't decode",
    "np.float64",
    "invalid literal",
    "unsupported operand",
    "has no attribute",
    "object is not",
    "index out of",
    "division by zero",
    "math domain error",
)

FUZZ = dict(deadline=None, database=None, suppress_health_check=list(HealthCheck), derandomize=False)


def cli(argv: list[str]) -> tuple[int, str, str, list[str]]:
    """Run ``orbit-env argv`` in this process: exit status, stdout, stderr, Python warnings raised."""
    out, err = io.StringIO(), io.StringIO()
    with (
        warnings.catch_warnings(record=True) as caught,
        contextlib.redirect_stdout(out),
        contextlib.redirect_stderr(err),
    ):
        warnings.simplefilter("always")
        try:
            status = main(argv)
        except SystemExit as exit_:  # argparse, through the one-line parser
            status = int(exit_.code or 0)
    return status, out.getvalue(), err.getvalue(), [f"{w.category.__name__}: {w.message}" for w in caught]


def check_failure(status: int, out: str, err: str, argv: list[str]) -> None:
    """A refused command: exactly one line on stderr, in the CLI's words, no traceback."""
    assert status == 2, (status, argv, err)
    assert out == "", (argv, out)
    assert err.count("\n") == 1 and err.endswith("\n"), (argv, err)
    assert re.match(r"orbit-env( [a-z-]+)?: ", err), (argv, err)  # argparse's errors name the command
    assert "Traceback" not in err, (argv, err)
    for internal in INTERNAL:
        assert internal not in err, (argv, err)


def check_clean_stderr(err: str, caught: list[str], argv: list[str]) -> None:
    """After a success, stderr holds only the CLI's own warnings, and Python raised none."""
    assert caught == [], (argv, caught)
    for line in err.splitlines():
        assert line.startswith("orbit-env: warning: "), (argv, err)


def kepler_period_s(radius_perigee_m: float, radius_apogee_m: float) -> float:
    a = 0.5 * (radius_perigee_m + radius_apogee_m)
    return 2.0 * math.pi * math.sqrt(a**3 / MU)


# ------------------------------------------------------------------------------------------
# What a user types: plausible numbers, extremes and junk.

JUNK = ["", " ", "abc", "nan", "inf", "-inf", "1e", "0x10", "--", "1,5", "1e999", "-0", "1_000", "٣"]


def number_text(low: float, high: float) -> st.SearchStrategy[str]:
    """Text of a number in [low, high] (most cases), an extreme, or junk."""
    plausible = st.floats(low, high, allow_nan=False).map(lambda x: f"{x:.6g}")
    extreme = st.sampled_from(["0", "-1", "1e300", "-1e300", "1e-300", "1e6", "-8.5", "200", "1100", "50000"])
    return st.one_of(plausible, plausible, plausible, extreme, st.sampled_from(JUNK))


def typed(argv: list[str], flag: str) -> str:
    """The value given to ``flag`` (either form of :func:`option`)."""
    for k, item in enumerate(argv):
        if item == flag:
            return argv[k + 1]
        if item.startswith(flag + "="):
            return item[len(flag) + 1 :]
    raise AssertionError(f"{flag} not in {argv}")


def option(flag: str, value: str) -> list[str]:
    # "--flag=value" also carries values argparse would take for a flag ("-inf").
    return [f"{flag}={value}"] if value.startswith("-") or value == "" else [flag, value]


@st.composite
def lifetime_argv(draw: st.DrawFn) -> list[str]:
    argv = ["lifetime"]
    perigee = draw(number_text(100, 1100))
    argv += option("--perigee", perigee)
    argv += option("--apogee", draw(st.one_of(number_text(100, 4000), st.just(perigee))))
    satellite = draw(st.sampled_from(["default", "mass-area", "load", "load", "both"]))
    if satellite in ("mass-area", "both"):
        argv += option("--mass", draw(number_text(0.1, 5000))) + option("--area", draw(number_text(0.01, 50)))
    if satellite in ("load", "both"):
        argv += option("--mass-per-area", draw(number_text(0.05, 2000)))
    if draw(st.booleans()):
        argv += option("--cx", draw(number_text(1.0, 4.0)))
    atmosphere = draw(st.sampled_from(["paper", "paper", "exponential"]))
    argv += ["--atmosphere", atmosphere]
    if atmosphere == "paper" and draw(st.integers(0, 3)) == 0:
        argv += option("--rho100", draw(number_text(1e-7, 1e-5)))
    if atmosphere == "exponential" and draw(st.booleans()):
        argv += option("--rho0", draw(number_text(1e-13, 1e-9)))
        argv += option("--h0-km", draw(number_text(150, 600)))
        argv += option("--scale-height-km", draw(number_text(20, 80)))
    if draw(st.integers(0, 2)) == 0:
        argv += option("--density-scale", draw(number_text(0.1, 10)))
    # Curves for a new exponential law take a second to build: the averaged ODE for those.
    if atmosphere == "paper":
        argv += ["--method", draw(st.sampled_from(["curves", "curves", "averaged"]))]
    if draw(st.integers(0, 3)) == 0:
        argv += ["--rotating-atmosphere", "--inclination", draw(st.sampled_from(["0", "51.6", "97.8"]))]
    elif draw(st.integers(0, 3)) == 0:
        argv += option("--inclination", draw(number_text(0, 180)))
    if atmosphere == "paper" and draw(st.integers(0, 3)) == 0 and "--rotating-atmosphere" not in argv:
        argv += option("--rule", draw(number_text(1, 30)))
    if draw(st.integers(0, 3)) > 0:
        argv.append("--json")
    return argv


def checked_run(argv: list[str]) -> str | None:
    """Run the command: its output if it succeeded (clean stderr, finite numbers), None if it failed as it should."""
    status, out, err, caught = cli(argv)
    if status != 0:
        check_failure(status, out, err, argv)
        return None
    check_clean_stderr(err, caught, argv)
    assert not NOT_FINITE.search(out), (argv, out)
    return out


def check_lifetime(argv: list[str]) -> None:
    out = checked_run(argv)
    if out is None:
        return
    hp_km, ha_km = float(typed(argv, "--perigee")), float(typed(argv, "--apogee"))
    if "--json" not in argv:
        days = float(re.search(r"^lifetime\s+(\S+) days", out, re.MULTILINE).group(1))
        assert days > 0.0 or hp_km <= 100.0, (argv, out)  # at 100 km the satellite re-enters now
        return
    summary = json.loads(out)
    for key in ("nu", "revolutions", "days", "years", "perigee_velocity_m_s"):
        value = summary[key]
        assert isinstance(value, float) and math.isfinite(value) and value >= 0.0, (argv, key, value)
        assert value > 0.0 or hp_km <= 100.0, (argv, key, value)  # at 100 km the satellite re-enters now
    assert summary["perigee_km"] == pytest.approx(hp_km) and summary["apogee_km"] == pytest.approx(ha_km)
    assert summary["years"] == pytest.approx(summary["days"] / 365.25, rel=1e-12)
    # The days are a sum of periods: between the revolutions times the period of the start orbit
    # and of a circular orbit at the re-entry height (with radii that bracket every height reference).
    shortest = kepler_period_s(R_LOW_M + 95e3, R_LOW_M + 95e3)
    longest = kepler_period_s(R_HIGH_M + hp_km * 1e3, R_HIGH_M + ha_km * 1e3)
    seconds = summary["days"] * 86400.0
    assert 0.99 * summary["revolutions"] * shortest <= seconds <= 1.01 * summary["revolutions"] * longest, (
        argv,
        summary,
    )

    # Vis-viva at the start perigee, with the radii that bracket every height reference.
    def vis_viva(radius_m: float, apogee_radius_m: float) -> float:
        return math.sqrt(MU * (2.0 / radius_m - 2.0 / (radius_m + apogee_radius_m)))

    low_v = vis_viva(R_HIGH_M + hp_km * 1e3, R_HIGH_M + ha_km * 1e3)
    high_v = vis_viva(R_LOW_M + hp_km * 1e3, R_LOW_M + ha_km * 1e3)
    assert 0.999 * low_v <= summary["perigee_velocity_m_s"] <= 1.001 * high_v, (argv, summary)
    if "rule_years" in summary:
        assert summary["dv_m_s"] >= 0.0
        if summary["complies"]:
            assert summary["dv_m_s"] == 0.0
        else:
            assert summary["dv_m_s"] > 0.0 and summary["new_perigee_km"] < hp_km


# ------------------------------------------------------------------------------------------
# fit-density: observation files and re-entries.


@st.composite
def observation_file(draw: st.DrawFn) -> tuple[str, str]:
    """A file's text and its time axis ("date" or "days")."""
    axis = draw(st.sampled_from(["date", "days"]))
    n = draw(st.integers(0, 6))
    start = draw(st.integers(0, 20000))
    steps = draw(st.lists(st.integers(-2, 40), min_size=n, max_size=n))
    lines = [f"{axis},perigee_km,apogee_km"]
    t = start
    hp = draw(st.floats(150, 600))
    ha = hp + draw(st.floats(0, 1500))
    for step in steps:
        t += step
        hp_i = hp - draw(st.floats(0, 20))
        ha_i = ha - draw(st.floats(0, 80))
        when = str(np.datetime64("1975-01-01") + np.timedelta64(t, "D")) if axis == "date" else f"{t * 0.5:g}"
        cells = [when, f"{hp_i:.4g}", f"{ha_i:.4g}"]
        if draw(st.integers(0, 8)) == 0:
            cells[draw(st.integers(0, 2))] = draw(st.sampled_from([*JUNK, "99999-01-01", "1900-01-01"]))
        lines.append(",".join(cells))
        if draw(st.integers(0, 10)) == 0:
            lines.append("")
        hp, ha = hp_i, ha_i
    return "\n".join(lines) + "\n", axis


@st.composite
def fit_case(draw: st.DrawFn) -> tuple[str, list[str]]:
    text, _ = draw(observation_file())
    argv: list[str] = []
    reentry = draw(st.integers(0, 3))
    if reentry == 1:
        argv += option("--reentry", draw(number_text(0, 30000)))
    elif reentry == 2:
        day = draw(st.integers(0, 20000))
        argv += ["--reentry", str(np.datetime64("1975-01-01") + np.timedelta64(day, "D"))]
    elif reentry == 3:
        argv += option("--reentry", draw(st.sampled_from([*JUNK, "2020-13-01", "99999-01-01"])))
    if draw(st.booleans()):
        argv += option("--mass-per-area", draw(number_text(1, 500)))
    if draw(st.integers(0, 3)) == 0:
        argv += option("--height-sigma-km", draw(number_text(0, 5)))
    argv += ["--atmosphere", draw(st.sampled_from(["paper", "paper", "exponential"]))]
    if draw(st.integers(0, 3)) > 0:
        argv.append("--json")
    return text, argv


def check_fit(tmp: Path, text: str, options: list[str]) -> None:
    path = tmp / "obs.csv"
    path.write_text(text)
    argv = ["fit-density", str(path), *options]
    out = checked_run(argv)
    if out is None:
        return
    if "--json" not in argv:
        assert re.search(r"^density scale\s+\S+", out, re.MULTILINE), out
        return
    fit = json.loads(out)
    scale, (low68, high68), (low95, high95) = fit["scale"], fit["interval68"], fit["interval95"]
    assert 1e-3 <= scale <= 1e3, (argv, fit)  # a scale an atmosphere can have, else refused
    assert math.isfinite(fit["sigma_log"]) and fit["sigma_log"] >= 0.0
    assert low95 <= low68 <= scale * (1 + 1e-12) and scale <= high68 * (1 + 1e-12) <= high95 * (1 + 1e-12)
    if fit["residual_rms_km"] is not None:
        assert math.isfinite(fit["residual_rms_km"]) and fit["residual_rms_km"] >= 0.0


# ------------------------------------------------------------------------------------------
# Batch files.

COLUMNS = {
    "name": st.sampled_from(["a", "sat 1", "x-2", ""]),
    "perigee_km": number_text(100, 1100),
    "apogee_km": number_text(100, 4000),
    "mass_kg": number_text(0.5, 2000),
    "area_m2": number_text(0.01, 20),
    "mass_per_area_kg_m2": number_text(0.1, 1000),
    "cx": number_text(1, 4),
    "inclination_deg": number_text(0, 180),
    "drag_parameter_m2_kg": number_text(1e-4, 0.5),
    "notes": st.sampled_from(["", "ok", "spare"]),
}


@st.composite
def batch_case(draw: st.DrawFn) -> tuple[bytes, int, list[int], list[str]]:
    """File bytes, the number of data rows, each data row's physical line, and the options."""
    names = draw(st.lists(st.sampled_from(sorted(COLUMNS)), unique=True, min_size=0, max_size=7))
    if draw(st.integers(0, 6)) > 0:
        names = sorted(set(names) | {"perigee_km", "apogee_km"}, key=lambda k: draw(st.integers(0, 9)))
    end = draw(st.sampled_from(["\n", "\r\n"]))
    lines = [",".join(names)]
    physical: list[int] = []
    for _ in range(draw(st.integers(0, 8))):
        while draw(st.integers(0, 8)) == 0:
            lines.append("")
        cells = [draw(COLUMNS[name]) for name in names]
        if draw(st.integers(0, 10)) == 0:
            cells.append(draw(st.sampled_from(["surplus", "", "9"])))
        if not any(cell.strip() for cell in cells):
            cells = ["sat", *cells[1:]] if cells else ["sat"]
            if not names:
                continue
        lines.append(",".join(cells))
        physical.append(len(lines))
    text = end.join(lines) + end
    data = text.encode()
    if draw(st.integers(0, 5)) == 0:
        data = "\ufeff".encode() + data
    options: list[str] = []
    if draw(st.integers(0, 4)) == 0:
        options += option("--rule", draw(number_text(1, 30)))
    if draw(st.integers(0, 4)) == 0:
        options += ["--atmosphere", "exponential"]  # the default law: its curves are built once
    if draw(st.integers(0, 3)) == 0:
        options += option("--inclination", draw(number_text(0, 180)))
    return data, len(physical), physical, options


def check_batch(tmp: Path, data: bytes, rows: int, lines: list[int], options: list[str], existing: bool) -> None:
    source, out = tmp / "sats.csv", tmp / "out.csv"
    source.write_bytes(data)
    out.unlink(missing_ok=True)
    if existing:
        out.write_text("earlier\n")
    argv = ["lifetime", "--batch", str(source), "--out", str(out), "--no-progress", *options]
    status, stdout, err, caught = cli(argv)
    if status == 2:
        check_failure(status, stdout, err, argv)
        assert (out.read_text() == "earlier\n") if existing else not out.exists()
        return
    assert not existing, (argv, "an existing file replaced without --force")
    assert status in (0, 1), (argv, status, err)
    if status == 0:
        check_clean_stderr(err, caught, argv)
    else:
        assert caught == [], (argv, caught)
        assert err.count("\n") == 1 and " rows have no lifetime (first: line " in err, (argv, err)
    assert f"wrote {rows} rows to {out}" in stdout, (argv, stdout)
    raw = out.read_bytes()
    assert b"\r" not in raw and raw.endswith(b"\n")
    records = list(csv.DictReader(io.StringIO(raw.decode())))
    assert len(records) == rows
    ok = 0
    for record, line in zip(records, lines, strict=True):
        for key, value in record.items():
            # Numbers are finite or empty; a name or a status may quote the "nan" a user typed.
            assert key in ("name", "status") or not NOT_FINITE.search(value), (argv, record)
        if record["status"] == "ok":
            ok += 1
            days = float(record["days"])
            assert math.isfinite(days) and (days > 0.0 or float(record["perigee_km"]) <= 100.0), (argv, record)
            assert float(record["years"]) == pytest.approx(days / 365.25, rel=1e-5, abs=1e-12)  # 6 digits each
            if "--rule" in " ".join(options):
                assert record["complies"] in ("true", "false") and float(record["dv_m_s"]) >= 0.0
        else:
            assert record["days"] == "" and record["status"].startswith(f"line {line}: "), (argv, record, line)
    assert (status == 0) == (ok == rows), (argv, status, ok, rows)


# ------------------------------------------------------------------------------------------
# The tests: the default run and the slow one share the checks.


@settings(max_examples=100, **FUZZ)
@given_(lifetime_argv())
def test_fuzz_lifetime(argv):
    check_lifetime(argv)


@settings(max_examples=70, **FUZZ)
@given_(fit_case())
def test_fuzz_fit_density(tmp_path_factory, case):
    check_fit(tmp_path_factory.mktemp("fit"), *case)


@settings(max_examples=70, **FUZZ)
@given_(batch_case(), st.integers(0, 9))
def test_fuzz_batch(tmp_path_factory, case, existing):
    check_batch(tmp_path_factory.mktemp("batch"), *case, existing=existing == 0)


@pytest.mark.slow
@settings(max_examples=5000, **FUZZ)
@given_(lifetime_argv())
def test_fuzz_lifetime_long(argv):
    check_lifetime(argv)


@pytest.mark.slow
@settings(max_examples=3000, **FUZZ)
@given_(fit_case())
def test_fuzz_fit_density_long(tmp_path_factory, case):
    check_fit(tmp_path_factory.mktemp("fit"), *case)


@pytest.mark.slow
@settings(max_examples=3000, **FUZZ)
@given_(batch_case(), st.integers(0, 9))
def test_fuzz_batch_long(tmp_path_factory, case, existing):
    check_batch(tmp_path_factory.mktemp("batch"), *case, existing=existing == 0)


# ------------------------------------------------------------------------------------------
# The environment: random valid configs and actions, 10^5 episodes through the vector env.


def random_config(rng: np.random.Generator) -> dict:
    low = float(rng.uniform(101.0, 900.0))
    high = float(rng.uniform(low, 1100.0))
    dry = float(rng.uniform(5.0, 500.0))
    sizes = tuple(float(x) for x in np.round(rng.uniform(0.0, 300.0, rng.integers(1, 6)), 1))
    scale_low = float(np.exp(rng.uniform(-2.5, 1.5)))
    return {
        "drag_coefficient": float(rng.uniform(1.0, 4.0)),
        "area_m2": float(np.exp(rng.uniform(-3.0, 3.0))),
        "dry_mass_kg": dry,
        "propellant_mass_kg": float(rng.uniform(0.0, dry)),
        "isp_s": float(rng.uniform(50.0, 450.0)),
        "burn_sizes_m_s": sizes,
        "max_burn_m_s": float(rng.uniform(1.0, 500.0)),
        "revolutions_per_step": float(rng.uniform(1.0, 80.0)),
        "horizon_steps": int(rng.integers(1, 40)),
        "propellant_cost_per_m_s": float(rng.uniform(0.0, 2.0)),
        "start_perigee_km": (low, high),
        "start_apogee_max_km": float(rng.uniform(high, 4000.0)),
        "scale_range": (scale_low, scale_low * float(np.exp(rng.uniform(0.0, 3.0)))),
        "cycle_amplitude": float(rng.choice([0.0, rng.uniform(0.0, 2.0)])),
        "cycle_period_days": float(rng.uniform(10.0, 5000.0)),
    }


def run_env_fuzz(episodes_wanted: int, seed: int = 0) -> dict[str, int]:
    """Step random missions until ``episodes_wanted`` episodes have ended; count what went wrong."""
    from orbit_env.envs.vector import OrbitRaisingVectorEnv

    rng = np.random.default_rng(seed)
    tally = {"configs": 0, "steps": 0, "episodes": 0, "nan": 0, "negative_height": 0, "perigee_above_apogee": 0}
    tally["negative_propellant"] = 0
    while tally["episodes"] < episodes_wanted:
        config = random_config(rng)
        continuous = bool(rng.integers(0, 2))
        env = OrbitRaisingVectorEnv(256, continuous=continuous, **config)
        tally["configs"] += 1
        obs, _ = env.reset(seed=int(rng.integers(2**31)))
        dry = config["dry_mass_kg"]
        for _ in range(3 * config["horizon_steps"] + 3):
            if continuous:
                action = rng.uniform(-1.0, 1.0, (env.num_envs, 1)).astype(np.float32)
            else:
                action = rng.integers(0, len(config["burn_sizes_m_s"]), env.num_envs)
            obs, reward, terminated, truncated, _ = env.step(action)
            state = env.task_state
            tally["steps"] += env.num_envs
            tally["episodes"] += int(np.count_nonzero(terminated | truncated))
            bad = ~np.isfinite(obs).all(axis=1) | ~np.isfinite(reward)
            bad |= ~np.isfinite(state.perigee_m) | ~np.isfinite(state.apogee_m) | ~np.isfinite(state.mass_kg)
            tally["nan"] += int(np.count_nonzero(bad))
            tally["negative_height"] += int(np.count_nonzero((state.perigee_m < 0.0) | (state.apogee_m < 0.0)))
            tally["perigee_above_apogee"] += int(np.count_nonzero(state.perigee_m > state.apogee_m * (1 + 1e-12)))
            tally["negative_propellant"] += int(np.count_nonzero(state.mass_kg < dry * (1 - 1e-12)))
        env.close()
    return tally


def test_env_fuzz_short():
    tally = run_env_fuzz(2000, seed=1)
    assert tally["episodes"] >= 2000
    assert tally["nan"] == tally["negative_height"] == 0
    assert tally["perigee_above_apogee"] == tally["negative_propellant"] == 0


@pytest.mark.slow
def test_env_fuzz_long():
    tally = run_env_fuzz(100_000, seed=2)
    print("env fuzz tally:", tally)
    assert tally["episodes"] >= 100_000
    assert tally["nan"] == tally["negative_height"] == 0, tally
    assert tally["perigee_above_apogee"] == tally["negative_propellant"] == 0, tally
