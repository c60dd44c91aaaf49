#!/usr/bin/env python3
"""Writes the report's fixed case set (docs/report.md) to stdout.

The case set is a grid per group, so it is regenerated exactly by
    /usr/bin/python3 scripts/make_cases.py > reference/cases/earth.csv
Columns are those of `skybake eval` plus `group`; empty distance_m means the
whole ray (sky radiance), empty normal_zenith_deg means no irradiance.
"""

import itertools
import sys

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


def main():
    out = sys.stdout
    out.write(",".join(COLUMNS) + "\n")
    for row in rows():
        out.write(",".join(str(v) for v in row) + "\n")


if __name__ == "__main__":
    main()
