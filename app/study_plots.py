# The integrator study's figures, drawn by `tickfx study --plots DIR` from the series CSVs it has
# just written into DIR (app/IntegratorStudy.h, writeStudySeriesCsv). Embedded in the tickfx
# binary and run with Debian's /usr/bin/python3: matplotlib is the only thing it needs.
import csv
import math
import os
import sys

MISSING = 3  # the exit status tickfx reads as "matplotlib is not installed"

try:
    import matplotlib

    matplotlib.use("Agg")  # files only: no display, no window system
    import matplotlib.pyplot as plt
except ImportError:
    sys.stderr.write("matplotlib for Python 3 is not installed\n")
    sys.exit(MISSING)

NAMES = {
    "explicit_euler": "explicit Euler",
    "semi_implicit_euler": "semi-implicit Euler",
    "midpoint": "midpoint",
    "position_verlet": "position Verlet",
    "velocity_verlet": "velocity Verlet",
    "rk4": "RK4",
}


def rows(directory, name):
    with open(os.path.join(directory, name), newline="") as f:
        return list(csv.DictReader(f))


def runs(table, *keys):
    """The rows grouped by the values of `keys`, in first-seen order: one run a group."""
    groups = {}
    for row in table:
        groups.setdefault(tuple(row[k] for k in keys), []).append(row)
    return groups


def column(run, key):
    return [float(r[key]) for r in run]


def save(figure, directory, name):
    # Written beside its final name, then renamed: a reader never sees half a PNG.
    path = os.path.join(directory, name)
    temporary = path + ".partial.png"
    figure.savefig(temporary, dpi=100)
    plt.close(figure)
    os.replace(temporary, path)
    return path


# The exact solution, drawn wide and faint under the simulated curves.
EXACT = {"color": "black", "linewidth": 3, "alpha": 0.3, "label": "exact"}


def titled(axes, title, xlabel, ylabel):
    """Titles an axes, names both axes with their units, and draws a light grid."""
    axes.set_title(title)
    axes.set_xlabel(xlabel)
    axes.set_ylabel(ylabel)
    axes.grid(True, alpha=0.3)


def constant_acceleration(directory):
    table = rows(directory, "series_constant_acceleration.csv")
    by_rate = runs(table, "step_rate_hz")
    figure, axes = plt.subplots(len(by_rate), 2, figsize=(12, 3.2 * len(by_rate)), squeeze=False)
    figure.suptitle("Constant acceleration a = -9.81 m/s², from rest: position and error")
    for (rate,), (left, right) in zip(by_rate, axes):
        exact_drawn = False
        for (integrator,), run in runs(by_rate[(rate,)], "integrator").items():
            t = column(run, "t")
            if not exact_drawn:
                left.plot(t, column(run, "exact"), **EXACT)
                exact_drawn = True
            left.plot(t, column(run, "position"), label=NAMES.get(integrator, integrator))
            right.plot(t, column(run, "error"), label=NAMES.get(integrator, integrator))
        titled(left, f"dt = 1/{rate} s: position", "time (s)", "position (m)")
        titled(right, f"dt = 1/{rate} s: error (simulated - exact)", "time (s)", "error (m)")
        right.legend(fontsize="small")
    figure.tight_layout(rect=(0, 0, 1, 0.98))
    return save(figure, directory, "constant_acceleration.png")


def oscillator(directory):
    table = rows(directory, "series_oscillator.csv")
    by_rate = runs(table, "step_rate_hz")
    figure, axes = plt.subplots(len(by_rate), 3, figsize=(15, 4.2 * len(by_rate)), squeeze=False)
    figure.suptitle("Harmonic oscillator k = 1 N/m, m = 1 kg, x0 = -1 m: exact x = -cos t, E = 0.5 J")
    for (rate,), (position, energy, phase) in zip(by_rate, axes):
        end = max(column(by_rate[(rate,)], "t"))
        fine = [end * i / 1000 for i in range(1001)]
        position.plot(fine, [-math.cos(t) for t in fine], **EXACT)
        for (integrator,), run in runs(by_rate[(rate,)], "integrator").items():
            label = NAMES.get(integrator, integrator)
            t = column(run, "t")
            position.plot(t, column(run, "position"), label=label)
            energy.plot(t, column(run, "energy"), label=label)
            phase.plot(column(run, "position"), column(run, "velocity"), label=label)
        titled(position, f"dt = 1/{rate} s: position", "time (s)", "position (m)")
        titled(energy, f"dt = 1/{rate} s: energy", "time (s)", "energy (J)")
        energy.axhline(0.5, **EXACT)
        energy.set_yscale("log")
        titled(phase, f"dt = 1/{rate} s: phase portrait", "position (m)", "velocity (m/s)")
        circle = plt.Circle((0, 0), 1.0, fill=False, **EXACT)
        phase.add_patch(circle)
        phase.set_aspect("equal", adjustable="datalim")
        energy.legend(fontsize="small")
    figure.tight_layout(rect=(0, 0, 1, 0.96))
    return save(figure, directory, "oscillator.png")


def wind(directory):
    table = rows(directory, "series_wind.csv")
    by_rate = runs(table, "step_rate_hz")
    frequency = table[0]["frequency_hz"] if table else "?"
    figure, (position, error) = plt.subplots(1, 2, figsize=(13, 4.5))
    figure.suptitle(f"Periodic wind a = 150·sin(2π·{frequency}·t) m/s², semi-implicit Euler")
    exact_drawn = False
    for (rate,), run in by_rate.items():
        t = column(run, "t")
        if not exact_drawn:
            fine = max(by_rate, key=lambda k: int(k[0]))
            tf = column(by_rate[fine], "t")
            position.plot(tf, column(by_rate[fine], "exact"), **EXACT)
            exact_drawn = True
        p = column(run, "position")
        position.plot(t, p, marker="." if int(rate) < 100 else None, label=f"{rate} Hz")
        error.plot(t, [a - b for a, b in zip(p, column(run, "exact"))], label=f"{rate} Hz")
    titled(position, f"position: the {frequency} Hz wind seen at each step rate", "time (s)",
          "position (m)")
    titled(error, "error (simulated - exact)", "time (s)", "error (m)")
    for a in (position, error):
        a.legend(fontsize="small")
    figure.tight_layout(rect=(0, 0, 1, 0.95))
    return save(figure, directory, "wind.png")


def main():
    directory = sys.argv[1]
    for draw in (constant_acceleration, oscillator, wind):
        print("wrote " + draw(directory))


if __name__ == "__main__":
    main()
