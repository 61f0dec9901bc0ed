"""`real-bench`: the figures of benchmarks/real_bench from what it writes into its output folder:
real_bench.csv (one row per set, variant, start and repetition; the first repetition is drawn),
SET/groundtruth.txt and
SET/RUN/aligned_trajectory.txt (TUM, the estimate after its Sim(3) alignment), RUN being the
variant, or VARIANT_START for a curve run from another start than the initialiser's (the bar
and line labels too).

  ate_by_set.png       ATE rmse per set, one bar per variant (log scale: the sets' units and
                       sizes differ by orders of magnitude); a variant that failed or was
                       skipped on a set has no bar.
  trajectories.png     per set, the ground-truth camera centres and every evaluated variant's
                       aligned ones, seen along the ground truth's direction of least spread
                       (top-down for a camera moving over a floor or road)."""
import math
import os

from .inputs import InputError, number, read_csv, read_tum

VARIANTS = ("init", "curves", "hybrid", "colmap")
COLUMNS = ("set", "variant", "status", "ate_rmse")


def read_rows(path):
    """The rows of the first repetition (--repetitions runs the same computation again for its
    time), each variant named as its run folder, ate_rmse a number."""
    rows = [r for r in read_csv(path, COLUMNS) if r.get("repetition", "1") in ("", "1")]
    if not rows:
        raise InputError("%s: no rows: nothing to draw" % path)
    for r in rows:
        r["ate_rmse"] = number(r, "ate_rmse", path)
        start = r.get("start", "")
        if start not in ("", "init"):
            r["variant"] = "%s_%s" % (r["variant"], start)
    return rows


def draw(out_dir):
    rows = read_rows(os.path.join(out_dir, "real_bench.csv"))
    sets = []
    for r in rows:
        if r["set"] not in sets:
            sets.append(r["set"])
    variants = [v for v in VARIANTS if any(r["variant"] == v for r in rows)]
    variants += sorted({r["variant"] for r in rows} - set(variants))
    from .mpl import save
    return (save(ate_figure(rows, sets, variants), os.path.join(out_dir, "ate_by_set.png"))
            + save(trajectory_figure(out_dir, rows, sets, variants),
                   os.path.join(out_dir, "trajectories.png")))


def ate_of(rows, s, v):
    for r in rows:
        if r["set"] == s and r["variant"] == v and r["status"] == "ok":
            return r["ate_rmse"]
    return float("nan")


def ate_figure(rows, sets, variants):
    from .mpl import label_bars, plt
    figure, axes = plt.subplots(figsize=(max(8, 1.6 * len(sets)), 6))
    width = 0.8 / len(variants)
    for index, v in enumerate(variants):
        offsets = [g + (index - (len(variants) - 1) / 2) * width for g in range(len(sets))]
        values = [ate_of(rows, s, v) for s in sets]
        # A zero or missing ATE cannot sit on a log axis: no bar.
        values = [x if x > 0 else float("nan") for x in values]
        label_bars(axes, axes.bar(offsets, values, width, label=v, color=colour(v, variants)))
    axes.set_yscale("log")
    axes.set_xticks(range(len(sets)))
    axes.set_xticklabels(sets, rotation=20, ha="right", fontsize=8)
    axes.set_title("Real sets: ATE rmse after Sim(3) alignment (no bar: failed or skipped)")
    axes.set_ylabel("ATE rmse (ground-truth unit)")
    axes.legend()
    axes.grid(alpha=0.3, axis="y", which="both")
    figure.tight_layout()
    return figure


def colour(variant, variants):
    index = VARIANTS.index(variant) if variant in VARIANTS else len(VARIANTS) + variants.index(variant)
    return "C%d" % index


def centres(path):
    return [pose[1] for pose in read_tum(path)]


def plane_axes(points):
    """The two directions of largest spread of `points` (the plane to draw them in)."""
    import numpy
    p = numpy.asarray(points, dtype=float)
    if len(p) < 3:
        return numpy.eye(3)[:2]
    _, _, vt = numpy.linalg.svd(p - p.mean(axis=0), full_matrices=False)
    return vt[:2]


def trajectory_figure(out_dir, rows, sets, variants):
    import numpy
    from .mpl import plt
    columns = min(3, len(sets))
    lines = int(math.ceil(len(sets) / columns))
    figure, grid = plt.subplots(lines, columns, figsize=(5 * columns, 4.5 * lines), squeeze=False)
    for index, s in enumerate(sets):
        axes = grid[index // columns][index % columns]
        truth = centres(os.path.join(out_dir, s, "groundtruth.txt"))
        plane = plane_axes(truth)
        xy = numpy.asarray(truth) @ plane.T
        axes.plot(xy[:, 0], xy[:, 1], color="black", linewidth=1.5, label="ground truth")
        for v in variants:
            if math.isnan(ate_of(rows, s, v)):
                continue
            path = os.path.join(out_dir, s, v, "aligned_trajectory.txt")
            xy = numpy.asarray(centres(path)) @ plane.T
            axes.plot(xy[:, 0], xy[:, 1], marker=".", markersize=3, linewidth=0.8,
                      color=colour(v, variants), label=v)
        axes.set_title(s, fontsize=9)
        axes.set_aspect("equal", adjustable="datalim")
        axes.grid(alpha=0.3)
        axes.legend(fontsize=7)
    for index in range(len(sets), lines * columns):
        grid[index // columns][index % columns].axis("off")
    figure.suptitle("Aligned camera centres (plane of largest spread)", fontsize=10)
    figure.tight_layout()
    return figure
