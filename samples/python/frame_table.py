#!/usr/bin/env python3
"""Runs samples/fountain.toml frame by frame at its output frame rate and prints, per frame, its
time, the particle count and the particles' bounding box: a starting point for pipeline scripts.

    PYTHONPATH=build/python /usr/bin/python3 samples/python/frame_table.py
"""
from pathlib import Path

import tickfx

# Relative to this script, so it runs from any working directory.
EFFECT = Path(__file__).resolve().parent.parent / "fountain.toml"


def main():
    system = tickfx.load_effect(EFFECT)
    # An exact Fraction of a second: frames add up to the effect's length without drift.
    frame = 1 / system.output_fps
    print(f"{EFFECT.name}: {system.output_frames} frames at {system.output_fps} fps, "
          f"{system.step_rate} Hz ticks")
    print(f"{'frame':>5} {'time (s)':>9} {'count':>6}   "
          f"{'min x':>8} {'min y':>8} {'min z':>8}   {'max x':>8} {'max y':>8} {'max z':>8}")
    for number in range(1, system.output_frames + 1):
        system.advance(frame)
        # The positions at the frame's own time (metres), as the frame's cache would hold them.
        positions = system.interpolated_positions()
        if len(positions) == 0:
            lo = hi = [float("nan")] * 3  # no particles, no box
        else:
            lo, hi = positions.min(axis=0), positions.max(axis=0)
        box = " ".join(f"{v:8.3f}" for v in lo) + "   " + " ".join(f"{v:8.3f}" for v in hi)
        print(f"{number:5d} {system.time:9.4f} {system.count:6d}   {box}")
    # The same 16 hex digits as `tickfx run samples/fountain.toml --hash`.
    print(f"state-hash: {system.state_hash()}")


if __name__ == "__main__":
    main()
