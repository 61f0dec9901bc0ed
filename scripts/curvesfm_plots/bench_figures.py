"""`planar-bench` and `strategy-bench`: the figures of the two benches, from the CSV files they
write into their output folder (planar_bench: runs.csv, paper_table2.csv; strategy_bench:
runs.csv). Each figure is written as NAME.png and NAME.pdf beside them."""
import os

from .inputs import InputError, number, read_csv

CATEGORIES = ("logo", "indoor", "outdoor")
STRATEGIES = ("joint", "alternating", "inner_iterations")
NOISE_LABEL = "intensity noise (% of 255)"


def mean(values):
    values = [v for v in values if v == v]
    return sum(values) / len(values) if values else float("nan")


# ----------------------------------------------------------------------------------------------
# planar_bench

def planar(out_dir):
    from .mpl import save_png_and_pdf
    runs_path = os.path.join(out_dir, "runs.csv")
    columns = ("category", "noise_percent", "initial_ate_mm", "refined_ate_mm", "ratio", "error")
    runs = read_csv(runs_path, columns)
    # A failed case (its message in `error`) has no ATE; the bench's tables leave it out too.
    ok = [{c: (r[c] if c in ("category", "error") else number(r, c, runs_path)) for c in columns}
          for r in runs if r["error"] == ""]
    if not ok:
        raise InputError("%s: no case without an error: nothing to draw" % runs_path)
    noises = sorted({r["noise_percent"] for r in ok})
    paper = read_paper_table(os.path.join(out_dir, "paper_table2.csv"))
    return (save_png_and_pdf(ratio_figure(ok, noises), out_dir, "ate_ratio_vs_noise")
            + save_png_and_pdf(paper_figure(ok, noises, paper), out_dir, "ate_vs_noise"))


def read_paper_table(path):
    rows = read_csv(path, ("category", "noise_percent", "ate_mm"))
    table = {}
    for r in rows:
        table.setdefault(r["category"], []).append(
            (number(r, "noise_percent", path), number(r, "ate_mm", path)))
    return table


def category_mean(ok, category, noise, column):
    return mean([r[column] for r in ok
                 if r["noise_percent"] == noise and category in (None, r["category"])])


def ratio_figure(ok, noises):
    from .mpl import GREY, plt
    figure, axes = plt.subplots(figsize=(8, 6))
    for category in CATEGORIES:
        axes.plot(noises, [category_mean(ok, category, n, "ratio") for n in noises], marker="o",
                  label=category)
    axes.axhline(1.0, color=GREY, linewidth=1, label="no improvement")
    axes.set_title("Planar experiment: refined / initial ATE (mean per category)")
    axes.set_xlabel(NOISE_LABEL)
    axes.set_ylabel("refined ATE / initial ATE")
    axes.legend()
    axes.grid(alpha=0.3)
    return figure


def paper_figure(ok, noises, paper):
    from .mpl import GREY, plt
    figure, axes = plt.subplots(figsize=(8, 6))
    for index, category in enumerate(CATEGORIES):
        colour = "C%d" % index
        axes.plot(noises, [category_mean(ok, category, n, "refined_ate_mm") for n in noises],
                  marker="o", color=colour, label=category + " (ours)")
        points = sorted(paper.get(category, []))
        axes.plot([p[0] for p in points], [p[1] for p in points], linestyle="--", color=colour,
                  linewidth=1, label=category + " (paper)")
    axes.plot(noises, [category_mean(ok, None, n, "initial_ate_mm") for n in noises], color=GREY,
              label="initial (mean of all)")
    axes.set_yscale("log")
    axes.set_title("Planar experiment: refined ATE vs the paper's Table 2")
    axes.set_xlabel(NOISE_LABEL)
    axes.set_ylabel("ATE (mm)")
    axes.legend(fontsize=8)
    axes.grid(alpha=0.3, which="both")
    return figure


# ----------------------------------------------------------------------------------------------
# strategy_bench

def strategy(out_dir):
    from .mpl import save_png_and_pdf
    path = os.path.join(out_dir, "runs.csv")
    text = ("scene", "strategy", "linear_solver", "kernel")
    values = ("lambda1", "lambda2", "ate_after_mm", "curve_after_mm", "seconds")
    runs = [{c: (r[c] if c in text else number(r, c, path)) for c in text + values}
            for r in read_csv(path, text + values)]
    if not runs:
        raise InputError("%s: no runs: nothing to draw" % path)
    return (save_png_and_pdf(error_vs_time(runs, "ate_after_mm", "Pose error vs time, every run",
                                           "ATE after BA (mm)"), out_dir, "error_vs_time")
            + save_png_and_pdf(error_vs_time(runs, "curve_after_mm",
                                             "Curve error vs time, every run",
                                             "curve error after BA (mm)"),
                               out_dir, "curve_error_vs_time")
            + save_png_and_pdf(weights_figure(runs), out_dir, "error_vs_weights")
            + save_png_and_pdf(kernels_figure(runs), out_dir, "error_by_kernel"))


def error_vs_time(runs, column, title, label):
    from .mpl import plt
    figure, axes = plt.subplots(figsize=(8, 6))
    for s in STRATEGIES:
        mine = [r for r in runs if r["strategy"] == s]
        axes.scatter([r["seconds"] for r in mine], [r[column] for r in mine], s=20, label=s)
    axes.set_xscale("log")
    axes.set_yscale("log")
    axes.set_title(title)
    axes.set_xlabel("solve time (s)")
    axes.set_ylabel(label)
    axes.legend()
    axes.grid(alpha=0.3, which="both")
    return figure


def config_mean(runs, column, **config):
    """Mean of `column` over the scenes of one configuration (NaN if it did not run)."""
    return mean([r[column] for r in runs if all(r[k] == v for k, v in config.items())])


def bar_groups(groups, series, title, xlabel, ylabel):
    """Grouped bars: `series` is [(label, [value per group])]."""
    from .mpl import label_bars, plt
    figure, axes = plt.subplots(figsize=(8, 6))
    width = 0.8 / len(series)
    for index, (label, values) in enumerate(series):
        offsets = [g + (index - (len(series) - 1) / 2) * width for g in range(len(groups))]
        label_bars(axes, axes.bar(offsets, values, width, label=label))
    axes.set_xticks(range(len(groups)))
    axes.set_xticklabels(groups)
    axes.set_title(title)
    axes.set_xlabel(xlabel)
    axes.set_ylabel(ylabel)
    axes.legend()
    axes.grid(alpha=0.3, axis="y")
    return figure


def weights_figure(runs):
    # Joint, sparse Schur, Huber: one bar per lambda2 in each lambda1 group.
    lambda1s, lambda2s = (0.0, 1e2, 1e4), (0.0, 1.0, 10.0)
    base = dict(strategy="joint", linear_solver="sparse_schur", kernel="huber")
    series = [("lambda2 = %g" % l2,
               [config_mean(runs, "curve_after_mm", lambda1=l1, lambda2=l2, **base)
                for l1 in lambda1s]) for l2 in lambda2s]
    return bar_groups(["lambda1 = 0", "lambda1 = 1e2", "lambda1 = 1e4"], series,
                      "Curve error vs weights (joint, sparse Schur, Huber)",
                      "lambda1 (segment length)", "curve error after BA (mm)")


def kernels_figure(runs):
    kernels = ("none", "huber", "cauchy")
    base = dict(linear_solver="sparse_schur", lambda1=1e2, lambda2=1.0)
    series = [(s, [config_mean(runs, "ate_after_mm", strategy=s, kernel=k, **base)
                   for k in kernels]) for s in STRATEGIES]
    return bar_groups(list(kernels), series,
                      "Pose error by kernel and strategy (sparse Schur, default weights)",
                      "robust kernel", "ATE after BA (mm)")
