#!/usr/bin/env python3
"""Writes the report's fixed case set (docs/report.md), the dense twilight set
(docs/accuracy.md, "Twilight case set"), the twilight set between whole
degrees (docs/accuracy.md, "Twilight: more mu_s texels after sunset") or the
horizon band (docs/accuracy.md, "The horizon band at sunset") to stdout.

Each case set is a grid per group, so it is regenerated exactly by
    /usr/bin/python3 scripts/make_cases.py > reference/cases/earth.csv
    /usr/bin/python3 scripts/make_cases.py twilight > reference/cases/earth_twilight.csv
    /usr/bin/python3 scripts/make_cases.py twilight-between > reference/cases/earth_twilight_between.csv
    /usr/bin/python3 scripts/make_cases.py horizon > reference/cases/earth_horizon.csv

The twilight sets' reference values, with their standard errors, are computed with
    /usr/bin/python3 scripts/make_cases.py twilight-reference build/cli/skybake \
        > reference/cases/earth_twilight_reference.csv
    /usr/bin/python3 scripts/make_cases.py twilight-between-reference build/cli/skybake \
        > reference/cases/earth_twilight_between_reference.csv
which run `skybake reference` once per sun range with the paths that range
needs (TWILIGHT_PATHS) and write the rows in the case set's order. The
horizon band's single scattering (the independent quadrature the tables'
single scattering is checked against) is
    /usr/bin/python3 scripts/make_cases.py horizon-single-reference build/cli/skybake \
        > reference/cases/earth_horizon_single_reference.csv
(`skybake reference --max-order 1 --paths 4096`, under a minute on 2 cores:
a relative standard error below 1 % on all but 5 of its 6558 values of at
least 1e-9 W m^-2 sr^-1 nm^-1, at most 6.3 %, away from a sun 92 degrees
down).
Columns are those of `skybake eval` plus `group`; empty distance_m means the
whole ray (sky radiance), empty normal_zenith_deg means no irradiance.
"""

import itertools
import math
import os
import subprocess
import sys
import tempfile

COLUMNS = ["group", "altitude_m", "view_zenith_deg", "sun_zenith_deg", "view_sun_azimuth_deg",
           "distance_m", "normal_zenith_deg"]


def rows():
    # Daylight sky from the ground: sun 10-80 deg, views from the zenith to
    # 80 deg, toward, across and away from the sun.
    for sun, view, azimuth in itertools.product([10, 30, 50, 70, 80], [0, 30, 60, 80], [0, 60, 180]):
        yield "daylight", 0, view, sun, azimuth, "", ""
    # Daylight from 1 and 10 km: up, oblique, and down toward the ground.
    for altitude, view, sun, azimuth in itertools.product([1000, 10000], [0, 60, 100], [30, 70], [0, 180]):
        yield "daylight", altitude, view, sun, azimuth, "", ""
    # Rays near the horizon from the ground, where the parameterization is
    # discontinuous and the optical depth largest.
    for view, sun, azimuth in itertools.product([84, 87, 89, 89.8], [30, 60, 80], [0, 180]):
        yield "horizon", 0, view, sun, azimuth, "", ""
    # Low sun and twilight: sun 84-100 deg.
    for sun, view, azimuth in itertools.product([84, 88, 92, 96, 100], [0, 60, 85], [0, 180]):
        yield "twilight", 0, view, sun, azimuth, "", ""
    # From 100 km (above the 60 km top): the limb and down through the
    # atmosphere (the ground's horizon is at a view zenith of 100.2 deg).
    for view, sun, azimuth in itertools.product([95, 99, 102, 110, 130], [30, 70], [0, 180]):
        yield "space", 100000, view, sun, azimuth, "", ""
    # Aerial perspective from the ground to points 1-100 km away, including
    # short near-horizontal segments, where table methods are weakest.
    for distance, view, (sun, azimuth) in itertools.product([1000, 3000, 10000, 30000, 100000], [60, 85, 89.5, 90],
                                                            [(30, 0), (70, 180)]):
        yield "aerial_perspective", 0, view, sun, azimuth, distance, ""
    # Sun and sky irradiance on a horizontal surface, sun from the zenith to
    # below the horizon.
    for altitude, sun in itertools.product([0, 1000, 10000], [0, 20, 40, 60, 75, 85, 90, 95]):
        yield "irradiance", altitude, 0, sun, 0, "", 0


# The sun from 88 to 102 degrees in 1 degree steps. Sky from the ground: the
# zenith; 85 and 89 degrees toward and away from the sun (the bright and the
# dark horizon); 60 and 80 degrees away from the sun, into the Earth's shadow
# as it rises. From 10 km: the zenith, 85 degrees either way, 95 degrees down
# toward the sun. From space (100 km): through the limb, 95, 99 and 102
# degrees, either way. Sky irradiance on horizontal ground at 0 and 10 km to
# sun 100 degrees. Aerial perspective from 100 m at low sun (84-90 degrees):
# views 60 and 85 degrees, either way, over 1, 5 and 20 km. The group names
# the sun range, so that `scripts/case_errors.py` reports each.
SUNS = range(88, 103)


def sun_range(sun):
    for low, high in [(88, 90), (91, 96), (97, 100), (101, 102)]:
        if low <= sun <= high:
            return f"{low}-{high}"
    raise ValueError(sun)


def twilight_rows():
    for sun in SUNS:
        group = "twilight_sky_sun_" + sun_range(sun)
        yield group, 0, 0, sun, 0, "", ""
        for view, azimuth in itertools.product([85, 89], [0, 180]):
            yield group, 0, view, sun, azimuth, "", ""
        for view in [60, 80]:
            yield group, 0, view, sun, 180, "", ""
        for view, azimuth in [(0, 0), (85, 0), (85, 180), (95, 0)]:
            yield group, 10000, view, sun, azimuth, "", ""
        for view, azimuth in itertools.product([95, 99, 102], [0, 180]):
            yield group, 100000, view, sun, azimuth, "", ""
    for sun, altitude in itertools.product(range(88, 101), [0, 10000]):
        yield "twilight_irradiance_sun_88-100", altitude, 0, sun, 0, "", 0
    for sun, view, azimuth, distance in itertools.product([84, 86, 88, 90], [60, 85], [0, 180], [1000, 5000, 20000]):
        yield "low_sun_aerial_perspective_sun_84-90", 100, view, sun, azimuth, distance, ""


def twilight_between_rows():
    """The sky with the sun between whole degrees, 1.2 degrees apart, so that
    its suns fall at every place between the scattering table's mu_s columns
    rather than where whole degrees happen to fall."""
    for sun in [90.5, 91.7, 92.9, 94.1, 95.3, 96.5, 97.7, 98.9]:
        group = "twilight_between_sun_" + ("90-93" if sun < 93.5 else "94-96" if sun < 97 else "97-99")
        for altitude in [0, 10000]:
            for view, azimuth in [(0, 0), (85, 0), (85, 180), (60, 90)]:
                yield group, altitude, view, sun, azimuth, "", ""


def horizon_rows():
    """The band around the horizon where a sunset is brightest: views every
    0.25 degrees from 87 to 93 degrees from the zenith, down to the horizon's
    dip from each camera (views below it end on the ground), suns 85-96
    degrees in whole degrees, toward, across and away from the sun, from the
    ground, 100 m, 1 km and 10 km."""
    earth_radius_m = 6360000.0
    for sun in range(85, 97):
        group = "horizon_sun_" + ("85-90" if sun <= 90 else "91-96")
        for altitude in [0, 100, 1000, 10000]:
            dip = math.degrees(math.acos(earth_radius_m / (earth_radius_m + altitude)))
            for view in [87 + 0.25 * i for i in range(25)]:
                if view > 90 + dip:
                    continue
                for azimuth in [0, 90, 180]:
                    yield group, altitude, f"{view:g}", sun, azimuth, "", ""


def horizon_single_reference(skybake):
    """The horizon band's single scattering: `skybake reference --max-order 1`."""
    with tempfile.TemporaryDirectory() as directory:
        lines = reference_lines(skybake, directory, "cases", list(horizon_rows()), "--paths", "4096",
                                "--max-order", "1")
    sys.stdout.write("\n".join(lines) + "\n")


def reference_lines(skybake, directory, name, cases, *options):
    """`skybake reference earth` of `cases` (written to DIRECTORY/NAME.csv)
    with `options`: its header line, then a line per case in their order."""
    cases_path = os.path.join(directory, f"{name}.csv")
    out_path = os.path.join(directory, f"{name}_reference.csv")
    with open(cases_path, "w") as f:
        f.write(",".join(COLUMNS) + "\n")
        for case in cases:
            f.write(",".join(str(v) for v in case) + "\n")
    subprocess.run([skybake, "reference", "earth", "--in", cases_path, "--out", out_path, *options, "--seed", "1",
                    "--threads", "2", "-q"], check=True)
    with open(out_path) as f:
        return f.read().splitlines()


# Paths per wavelength by the sun's zenith angle (up to the first bound), so
# that the reference's standard error stays within about 1 % to sun 100
# degrees and 3 % beyond (docs/accuracy.md, "Twilight case set"): deep
# twilight needs the most.
TWILIGHT_PATHS = [(93, 65536), (96, 131072), (100, 262144), (102, 131072)]


def twilight_paths(sun):
    return next(paths for bound, paths in TWILIGHT_PATHS if sun <= bound)


def twilight_reference(skybake, cases):
    """A twilight set's reference: one `skybake reference` run per path count."""
    results = [None] * len(cases)
    header = None
    with tempfile.TemporaryDirectory() as directory:
        for paths in sorted({paths for _, paths in TWILIGHT_PATHS}):
            chosen = [i for i, case in enumerate(cases) if twilight_paths(case[3]) == paths]
            if not chosen:
                continue
            lines = reference_lines(skybake, directory, f"cases_{paths}", [cases[i] for i in chosen], "--paths",
                                    str(paths))
            header = lines[0]
            for i, line in zip(chosen, lines[1:]):
                results[i] = line
    sys.stdout.write(header + "\n" + "\n".join(results) + "\n")


def main():
    sets = {"twilight": twilight_rows, "twilight-between": twilight_between_rows, "horizon": horizon_rows}
    name = sys.argv[1] if len(sys.argv) > 1 else ""
    if len(sys.argv) == 3 and name == "horizon-single-reference":
        horizon_single_reference(sys.argv[2])
        return
    if len(sys.argv) == 3 and name.removesuffix("-reference") in sets and name.endswith("-reference"):
        twilight_reference(sys.argv[2], list(sets[name.removesuffix("-reference")]()))
        return
    out = sys.stdout
    out.write(",".join(COLUMNS) + "\n")
    for row in sets[name]() if name in sets else rows():
        out.write(",".join(str(v) for v in row) + "\n")


if __name__ == "__main__":
    main()
