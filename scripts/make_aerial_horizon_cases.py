#!/usr/bin/env python3
"""Writes the near-horizon aerial-perspective cases (shaders_runtime/README.md,
"Aerial perspective near the horizon") to stdout:
    /usr/bin/python3 scripts/make_aerial_horizon_cases.py > reference/cases/earth_aerial_horizon.csv

Segments of 100 m, 1 km and 5 km at view zenith 85, 90 and 95 degrees, for
three suns (toward, across and away from the view), from cameras at 0 and
500 m; from the ground a ray at 95 degrees enters the ground at once, so that
view is taken from 500 m only (a 5 km segment there ends 0.56 km up). One
more query is the table method's worst case measured before the fix (100 m
up, 88 degrees, 1 km). Columns are those of `skybake eval` plus `group`.
"""

import itertools
import sys

COLUMNS = ["group", "altitude_m", "view_zenith_deg", "sun_zenith_deg", "view_sun_azimuth_deg",
           "distance_m", "normal_zenith_deg"]
SUNS = [(30, 0), (60, 90), (80, 180)]  # (zenith, azimuth from the view), degrees


def rows():
    for altitude, views in [(0, [85, 90]), (500, [85, 90, 95])]:
        for view, (sun, azimuth), distance in itertools.product(views, SUNS, [100, 1000, 5000]):
            yield "aerial_horizon", altitude, view, sun, azimuth, distance, ""
    for sun, azimuth in SUNS:
        yield "aerial_horizon", 100, 88, sun, azimuth, 1000, ""


def main():
    sys.stdout.write(",".join(COLUMNS) + "\n")
    for row in rows():
        sys.stdout.write(",".join(str(v) for v in row) + "\n")


if __name__ == "__main__":
    main()
