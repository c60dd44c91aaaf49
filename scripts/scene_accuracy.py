#!/usr/bin/python3
"""Accuracy of a scene's bake inside the scene, against the full bake.

Restricts the reference case set (reference/cases/earth_reference.csv, the
Monte Carlo values with their query columns) to the queries the scene of
SCENE_LUT can answer (its effects, camera altitudes, sun range, aerial
distance and object altitudes, read from the manifest), answers them with
`skybake eval` from SCENE_LUT and from FULL_LUT, and prints the relative
error of each against the reference, per quantity:

    /usr/bin/python3 scripts/scene_accuracy.py build/cli/skybake SCENE_LUT FULL_LUT \
        [reference/cases/earth_reference.csv]
"""
import csv
import io
import json
import math
import subprocess
import sys

import numpy as np

QUERY_COLUMNS = ["group", "altitude_m", "view_zenith_deg", "sun_zenith_deg", "view_sun_azimuth_deg",
                 "distance_m", "normal_zenith_deg"]


def inside(row, scene, bottom_radius):
    e = scene["effects"]
    altitude = float(row["altitude_m"])
    sun = float(row["sun_zenith_deg"])
    distance = float(row["distance_m"]) if row["distance_m"] else 0.0
    if row["normal_zenith_deg"] and not e["ground_irradiance"]:
        return False
    if distance > 0 and not e["aerial_perspective"]:
        return False
    if distance == 0 and not e["sky"]:
        return False
    lo, hi = scene["camera_altitude_m"]
    if not lo <= altitude <= hi:
        return False
    lo, hi = scene["sun_zenith_deg"]
    if not lo <= sun <= hi:
        return False
    if distance > 0:
        if distance > e["aerial_perspective_max_distance_m"]:
            return False
        # The geometry of skybake eval (shaders_runtime/query.h).
        vz = math.radians(float(row["view_zenith_deg"]))
        r = bottom_radius + altitude
        x, z = distance * math.sin(vz), r + distance * math.cos(vz)
        object_altitude = math.hypot(x, z) - bottom_radius
        lo, hi = scene["object_altitude_m"]
        if not lo - 1 <= object_altitude <= hi + 1:
            return False
    return True


def evaluate(skybake, lut, queries_csv):
    out = subprocess.run([skybake, "eval", lut, "--in", "/dev/stdin"], input=queries_csv, capture_output=True,
                         text=True, check=True).stdout
    return list(csv.DictReader(io.StringIO(out)))


def main():
    skybake, scene_lut, full_lut = sys.argv[1:4]
    reference_file = sys.argv[4] if len(sys.argv) > 4 else "reference/cases/earth_reference.csv"
    manifest = json.load(open(scene_lut + "/skybake.json"))
    scene = manifest["scene"]
    bottom_radius = manifest["parameters"]["bottom_radius"]
    rows = [r for r in csv.DictReader(open(reference_file)) if inside(r, scene, bottom_radius)]
    text = io.StringIO()
    writer = csv.DictWriter(text, QUERY_COLUMNS, extrasaction="ignore", lineterminator="\n")
    writer.writeheader()
    writer.writerows(rows)
    results = {name: evaluate(skybake, lut, text.getvalue()) for name, lut in (("scene", scene_lut), ("full", full_lut))}
    groups = sorted(set(r["group"] for r in rows))
    print(f"scene {scene['name']}: {len(rows)} reference queries inside it ({', '.join(groups)})")
    channels = [k[len("radiance_"):] for k in rows[0] if k.startswith("radiance_") and "stderr" not in k]
    for quantity in ("radiance", "transmittance", "sun_irradiance", "sky_irradiance"):
        keys = [f"{quantity}_{c}" for c in channels]
        if not rows[0].get(keys[0]) and not any(r.get(keys[0]) for r in rows):
            continue
        line = f"  {quantity:14s}"
        for name in ("scene", "full"):
            errors = []
            for ref, got in zip(rows, results[name]):
                for k in keys:
                    if ref.get(k) and got.get(k) and float(ref[k]) > 0:
                        errors.append(abs(float(got[k]) - float(ref[k])) / float(ref[k]))
            if not errors:
                continue
            errors = np.array(errors)
            line += (f"  {name}: mean {errors.mean():.4%} rms {math.sqrt((errors ** 2).mean()):.4%} "
                     f"max {errors.max():.4%} ({errors.size} values)")
        print(line)
    stderr_keys = [f"radiance_stderr_{c}" for c in channels]
    noise = [float(r[s]) / float(r[f"radiance_{c}"]) for r in rows for s, c in zip(stderr_keys, channels)
             if r.get(s) and r.get(f"radiance_{c}") and float(r[f"radiance_{c}"]) > 0]
    if noise:
        print(f"  reference noise (radiance stderr / value): mean {np.mean(noise):.4%} max {np.max(noise):.4%}")


if __name__ == "__main__":
    main()
