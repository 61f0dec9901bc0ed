"""`eval`: the figure of `curvesfm eval --plot`, from the JSON of `curvesfm eval --json`.

Left, the top view of the ground-truth and the aligned estimated camera centres in the plane of
largest spread, at equal scale; right, the ATE of every matched pose over time with its rmse. The
alignment is the one curvesfm computed (per_pose.aligned_position), never redone here.
"""
from .inputs import NUMBER, InputError, field, numbers, read_json

AXIS_NAMES = "xyz"


def top_view_axes(positions):
    """(horizontal, vertical) axes of the plane of largest spread: drops the axis along which the
    positions extend least; ties drop y, then x, so a flat or empty track gets x-z, the top view
    of a camera-convention (y down) world."""
    spans = [max(p[a] for p in positions) - min(p[a] for p in positions) if positions else 0.0
             for a in range(3)]
    dropped = 1
    for a in (0, 2):
        if spans[a] < spans[dropped]:
            dropped = a
    return (1 if dropped == 0 else 0, 1 if dropped == 2 else 2)


def read_evaluation(path):
    document = read_json(path)
    per_pose = {key: numbers(document, path, "per_pose." + key, width)
                for key, width in (("ground_truth_timestamp", None), ("ate_m", None),
                                   ("aligned_position", 3), ("ground_truth_position", 3))}
    if len({len(values) for values in per_pose.values()}) != 1:
        counts = ", ".join("%s %d" % (key, len(values)) for key, values in per_pose.items())
        raise InputError("%s: the per_pose lists differ in length (%s)" % (path, counts))
    per_pose["rmse"] = field(document, path, "ate_m.rmse", NUMBER)
    per_pose["alignment"] = field(document, path, "options.alignment", str)
    return per_pose


def draw(json_path, out_path):
    from .mpl import GREY, plt, save
    e = read_evaluation(json_path)
    figure, (top, ate) = plt.subplots(1, 2, figsize=(16, 6))
    draw_top_view(top, e, GREY)
    draw_ate(ate, e)
    figure.tight_layout()
    save(figure, out_path)


def draw_top_view(axes, e, grey):
    truth, estimate = e["ground_truth_position"], e["aligned_position"]
    h, v = top_view_axes(truth)
    # Markers would bury the line of a long trajectory; a short one shows its poses.
    marker = "o" if len(truth) <= 60 else None
    # The ground truth goes wide and grey under the estimate, so both show where they coincide.
    axes.plot([p[h] for p in truth], [p[v] for p in truth], color=grey, linewidth=4,
              marker=marker, markersize=4, label="ground truth")
    axes.plot([p[h] for p in estimate], [p[v] for p in estimate], linewidth=1.5, marker=marker,
              markersize=3, label="estimate (%s-aligned)" % e["alignment"])
    axes.set_aspect("equal", adjustable="datalim")
    axes.set_title("Top view: %s-%s plane (largest spread)" % (AXIS_NAMES[h], AXIS_NAMES[v]))
    axes.set_xlabel("%s (m)" % AXIS_NAMES[h])
    axes.set_ylabel("%s (m)" % AXIS_NAMES[v])
    axes.legend(loc="upper left")
    axes.grid(alpha=0.3)


def draw_ate(axes, e):
    times = e["ground_truth_timestamp"]
    start = times[0] if times else 0.0
    time = [t - start for t in times]
    axes.plot(time, e["ate_m"], marker="o" if len(time) <= 60 else None, markersize=3,
              label="ATE")
    if time:
        axes.plot([time[0], time[-1]], [e["rmse"]] * 2, linewidth=2,
                  label="rmse %.4g m" % e["rmse"])
    top = max(e["ate_m"] + [e["rmse"]])
    axes.set_ylim(0.0, 1.08 * top if top > 0 else 1.0)
    axes.set_title("ATE per matched pose (%s alignment)" % e["alignment"])
    axes.set_xlabel("time since the first match (s)")
    axes.set_ylabel("position error (m)")
    axes.legend(loc="upper left")
    axes.grid(alpha=0.3)
