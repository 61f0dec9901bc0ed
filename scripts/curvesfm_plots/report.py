"""`report`: a self-contained interactive HTML report of one `curvesfm run` output folder.

Reads report.json and curves.obj (required), trajectory.txt, trajectory_initial.txt and
overlays/*.png (optional; what is missing is left out with a note in the page). plotly.js is
embedded inline, the overlay thumbnails as base64 PNG: the page needs no network.
"""
import base64
import glob
import html
import io
import math
import os

from .eval_figure import AXIS_NAMES, top_view_axes
from .inputs import NUMBER, InputError, field, numbers, read_json, read_obj, read_tum

STAGES = ("undistort", "edges", "field", "depth", "correspondence", "initialise", "local_ba")
THUMBNAIL_WIDTH = 240  # px: small enough that 30 keyframes stay a light page.
GOLDEN = 0.618033988749895  # Spreads the colours of neighbouring curve indices apart.
FRUSTUM_DEPTH = 0.06  # Of the 3D map's largest extent.


def build(run_dir, out_path=None):
    out_path = out_path or os.path.join(run_dir, "report.html")
    try:
        import plotly.graph_objects as go
        import plotly.offline
    except ImportError:
        raise InputError("plotly is missing (Debian: apt-get install python3-plotly)")
    run = load_run(run_dir)
    figures = [(name, title, figure) for name, title, figure in (
        ("map", "3D curve map and keyframes", map_figure(go, run)),
        ("trajectory", "Trajectories", trajectory_figure(go, run)),
        ("ate", "ATE over time", ate_figure(go, run)),
        ("timings", "Per-stage time per keyframe", timings_figure(go, run)),
        ("costs", "Global BA cost per factor type", costs_figure(go, run))) if figure]
    page = render_page(run, figures, plotly.offline.get_plotlyjs(), thumbnails(run))
    try:
        with open(out_path, "w") as f:
            f.write(page)
    except OSError as e:
        raise InputError("%s: cannot write: %s" % (out_path, e.strerror))
    return out_path, {name: len(figure.data) for name, _, figure in figures}


# ----------------------------------------------------------------------------------------------
# Inputs

def load_run(run_dir):
    report_path = os.path.join(run_dir, "report.json")
    run = {"dir": run_dir, "notes": [], "report_path": report_path,
           "report": read_json(report_path)}
    field(run["report"], report_path, "frames", list)
    run["curves"] = read_obj(os.path.join(run_dir, "curves.obj"))
    run["keyframes"] = optional_tum(run, "trajectory.txt", "keyframe frusta")
    run["initial"] = optional_tum(run, "trajectory_initial.txt", "the initial trajectory")
    run["camera"] = optional_camera(run)
    run["per_pose"] = optional_per_pose(run)
    return run


def optional_tum(run, name, what):
    path = os.path.join(run["dir"], name)
    if not os.path.exists(path):
        run["notes"].append("No %s: %s left out." % (name, what))
        return []
    return read_tum(path)


def optional_camera(run):
    camera = run["report"].get("camera")
    if camera is None:
        run["notes"].append("report.json has no camera (an older curvesfm run): keyframes are "
                            "drawn as points, without frusta.")
        return None
    path = run["report_path"]
    return {key: field(run["report"], path, "camera." + key, NUMBER)
            for key in ("width", "height", "fx", "fy", "cx", "cy")}


def optional_per_pose(run):
    ate = field(run["report"], run["report_path"], "ate", dict) if "ate" in run["report"] else {}
    if not ate.get("per_pose"):
        problem = ate.get("problem")
        run["notes"].append("No ground truth to compare with%s: the trajectories are drawn as "
                            "estimated and the ATE is left out."
                            % (" (%s)" % problem if problem else ""))
        return None
    path = run["report_path"]
    return {which: {key: numbers(run["report"], path, "ate.per_pose.%s.%s" % (which, key), width)
                    for key, width in (("timestamp", None), ("error_m", None),
                                       ("aligned_position", 3), ("ground_truth_position", 3))}
            for which in ("initial", "refined")}


# ----------------------------------------------------------------------------------------------
# Geometry

def rotation(q):
    """Rotation matrix (rows) of the unit quaternion (qx, qy, qz, qw)."""
    x, y, z, w = q
    n = math.sqrt(x * x + y * y + z * z + w * w) or 1.0
    x, y, z, w = x / n, y / n, z / n, w / n
    return ((1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)),
            (2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)),
            (2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)))


def to_world(pose, point_in_cam):
    _, t, q = pose
    r = rotation(q)
    return tuple(sum(r[i][j] * point_in_cam[j] for j in range(3)) + t[i] for i in range(3))


def frustum_lines(pose, camera, depth):
    """Segments from the centre to the four image corners at `depth`, and the image rectangle."""
    corners = [to_world(pose, ((u - camera["cx"]) / camera["fx"] * depth,
                               (v - camera["cy"]) / camera["fy"] * depth, depth))
               for u, v in ((0, 0), (camera["width"], 0), (camera["width"], camera["height"]),
                            (0, camera["height"]))]
    centre = tuple(pose[1])
    lines = [[centre, corner] for corner in corners]
    return lines + [corners + [corners[0]]]


def joined(lines):
    """x, y, z lists of polylines separated by None, so one trace draws them all."""
    xs, ys, zs = [], [], []
    for line in lines:
        for p in line:
            xs.append(p[0])
            ys.append(p[1])
            zs.append(p[2])
        xs.append(None)
        ys.append(None)
        zs.append(None)
    return xs, ys, zs


# ----------------------------------------------------------------------------------------------
# Figures (each returns a plotly Figure, or None when its data is missing)

def map_figure(go, run):
    xs, ys, zs, colours, names = [], [], [], [], []
    for index, (name, lines) in enumerate(run["curves"]):
        x, y, z = joined(lines)
        xs += x
        ys += y
        zs += z
        colours += [(index * GOLDEN) % 1.0] * len(x)
        names += [name] * len(x)
    traces = [go.Scatter3d(x=xs, y=ys, z=zs, mode="lines", name="curves (%d)" % len(run["curves"]),
                           text=names, hoverinfo="text",
                           line=dict(color=colours, colorscale="Turbo", cmin=0, cmax=1, width=3))]
    keyframes = run["keyframes"]
    lo, hi = view_box(run, [pose[1] for pose in keyframes])
    size = max(h - l for l, h in zip(lo, hi)) or 1.0
    if keyframes:
        if run["camera"]:
            # Deep enough to see at the map's scale; neighbouring frusta may overlap.
            depth = FRUSTUM_DEPTH * size
            x, y, z = joined([line for pose in keyframes
                              for line in frustum_lines(pose, run["camera"], depth)])
            traces.append(go.Scatter3d(x=x, y=y, z=z, mode="lines", hoverinfo="skip",
                                       name="keyframes (%d)" % len(keyframes),
                                       line=dict(color="rgb(90,90,90)", width=2)))
        x, y, z = joined([[pose[1] for pose in keyframes]])
        traces.append(go.Scatter3d(x=x, y=y, z=z, mode="lines+markers", name="camera path",
                                   text=["keyframe %d" % k for k in range(len(keyframes))],
                                   marker=dict(size=2, color="black"),
                                   line=dict(color="black", width=2)))
    figure = go.Figure(traces)
    axes = {name + "axis": dict(range=[l, h]) for name, l, h in zip("xyz", lo, hi)}
    ratio = {name: (h - l) / size for name, l, h in zip("xyz", lo, hi)}
    figure.update_layout(scene=dict(aspectmode="manual", aspectratio=ratio, **axes), height=700,
                         margin=dict(l=0, r=0, t=30, b=0))
    return figure


def view_box(run, centres):
    """Axis ranges around the 2nd to 98th percentile of the curve samples and every camera centre:
    a few stray curves metres away would otherwise shrink the map to a dot. Notes how many curves
    reach beyond it."""
    import numpy
    samples = numpy.array([p for _, lines in run["curves"] for line in lines for p in line]
                          or [(0.0, 0.0, 0.0)])
    lo = numpy.percentile(samples, 2, axis=0)
    hi = numpy.percentile(samples, 98, axis=0)
    if centres:
        lo = numpy.minimum(lo, numpy.min(centres, axis=0))
        hi = numpy.maximum(hi, numpy.max(centres, axis=0))
    pad = 0.05 * max(hi - lo) or 0.05
    lo, hi = lo - pad, hi + pad
    outside = sum(1 for _, lines in run["curves"]
                  if any(not all(l <= c <= h for c, l, h in zip(p, lo, hi))
                         for line in lines for p in line))
    if outside:
        run["notes"].append("%d of %d curves reach beyond the box the 3D map shows (the 2nd to "
                            "98th percentile of the samples and the cameras); zoom out to see "
                            "them." % (outside, len(run["curves"])))
    return lo.tolist(), hi.tolist()


def trajectory_figure(go, run):
    per_pose = run["per_pose"]
    if per_pose:
        tracks = [("ground truth", per_pose["refined"]["ground_truth_position"]),
                  ("initial (sim3-aligned)", per_pose["initial"]["aligned_position"]),
                  ("refined (sim3-aligned)", per_pose["refined"]["aligned_position"])]
    else:
        tracks = [(name, [pose[1] for pose in run[key]])
                  for name, key in (("initial", "initial"), ("refined", "keyframes"))
                  if run[key]]
    if not tracks:
        return None
    h, v = top_view_axes(tracks[0][1])
    styles = {"ground truth": dict(color="rgb(150,150,150)", width=6)}
    figure = go.Figure([go.Scatter(x=[p[h] for p in track], y=[p[v] for p in track],
                                   mode="lines+markers", name=name, marker=dict(size=4),
                                   line=styles.get(name, dict(width=2)))
                        for name, track in tracks])
    figure.update_layout(
        title="Top view: %s-%s plane (largest spread)" % (AXIS_NAMES[h], AXIS_NAMES[v]),
        xaxis_title="%s (m)" % AXIS_NAMES[h], yaxis_title="%s (m)" % AXIS_NAMES[v],
        yaxis=dict(scaleanchor="x", scaleratio=1), height=550)
    return figure


def ate_figure(go, run):
    per_pose = run["per_pose"]
    if not per_pose:
        return None
    traces = []
    for which in ("initial", "refined"):
        times = per_pose[which]["timestamp"]
        start = times[0] if times else 0.0
        traces.append(go.Scatter(x=[t - start for t in times], y=per_pose[which]["error_m"],
                                 mode="lines+markers", name=which))
    figure = go.Figure(traces)
    figure.update_layout(xaxis_title="time since the first keyframe (s)",
                         yaxis_title="position error after Sim(3) alignment (m)", height=450)
    return figure


def timings_figure(go, run):
    path = run["report_path"]
    keyframes = [frame for frame in run["report"]["frames"]
                 if isinstance(frame, dict) and frame.get("keyframe_index", -1) >= 0]
    if not keyframes:
        run["notes"].append("report.json lists no keyframe: the timings are left out.")
        return None
    seconds = [field(frame, path, "seconds", dict) for frame in keyframes]
    index = [frame["keyframe_index"] for frame in keyframes]
    figure = go.Figure([go.Bar(x=index, y=[1e3 * s.get(stage, 0.0) for s in seconds], name=stage)
                        for stage in STAGES])
    figure.update_layout(barmode="stack", xaxis_title="keyframe", yaxis_title="wall time (ms)",
                         height=450)
    return figure


def costs_figure(go, run):
    costs = run["report"].get("global_ba_cost_by_type") or {}
    if not costs.get("initial") or not costs.get("final"):
        run["notes"].append("report.json has no global BA costs (global BA did not run): the "
                            "costs per factor type are left out.")
        return None
    path = run["report_path"]
    types = sorted(set(costs["initial"]) | set(costs["final"]))
    traces = []
    for when in ("initial", "final"):
        entries = [costs[when].get(t, {}) for t in types]
        values = [e.get("cost") for e in entries]
        if not all(isinstance(c, NUMBER) for c in values):
            raise InputError('%s: "global_ba_cost_by_type.%s" should map each factor type to '
                             "{count, cost}" % (path, when))
        traces.append(go.Bar(x=types, y=values, name=when,
                             text=["%d factors" % e.get("count", 0) for e in entries]))
    figure = go.Figure(traces)
    figure.update_layout(barmode="group", yaxis_type="log", yaxis_title="cost", height=450)
    return figure


def thumbnails(run):
    """[(name, base64 PNG)] of overlays/*.png scaled to THUMBNAIL_WIDTH."""
    paths = sorted(glob.glob(os.path.join(run["dir"], "overlays", "*.png")))
    if not paths:
        run["notes"].append("No overlays/*.png (run with --overlays): thumbnails left out.")
        return []
    import matplotlib.image
    result = []
    for path in paths:
        try:
            image = matplotlib.image.imread(path)
        except (OSError, ValueError, SyntaxError) as e:
            raise InputError("%s: cannot read as PNG: %s" % (path, e))
        step = max(1, math.ceil(image.shape[1] / THUMBNAIL_WIDTH))
        buffer = io.BytesIO()
        matplotlib.image.imsave(buffer, image[::step, ::step], format="png")
        result.append((os.path.basename(path), base64.b64encode(buffer.getvalue()).decode()))
    return result


# ----------------------------------------------------------------------------------------------
# Page

PAGE = """<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{title}</title>
<style>
body {{ font-family: sans-serif; margin: 1.5em; color: #222; }}
table {{ border-collapse: collapse; }} td, th {{ padding: 2px 10px; text-align: left; }}
.note {{ color: #8a5a00; }} .thumbs img {{ margin: 4px; border: 1px solid #ccc; }}
figure {{ display: inline-block; margin: 4px; }} figcaption {{ font-size: 80%; }}
</style>
<script>
// Errors and each figure's trace count land in #report-status, so that a headless browser test
// can read them from the DOM.
window.reportErrors = [];
window.addEventListener("error", function (e) {{ window.reportErrors.push(String(e.message)); }});
window.addEventListener("unhandledrejection", function (e) {{
  window.reportErrors.push("unhandled rejection: " + String(e.reason));
}});
(function () {{
  var original = console.error;
  console.error = function () {{
    window.reportErrors.push(Array.prototype.join.call(arguments, " "));
    original.apply(console, arguments);
  }};
}})();
</script>
<script>{plotlyjs}</script>
</head><body>
<h1>{title}</h1>
{summary}
{notes}
{sections}
<pre id="report-status" hidden></pre>
<script>
window.addEventListener("load", function () {{
  setTimeout(function () {{
    var traces = {{}};
    document.querySelectorAll(".plotly-graph-div").forEach(function (gd) {{
      traces[gd.id] = gd.data ? gd.data.length : -1;
    }});
    document.getElementById("report-status").textContent =
        JSON.stringify({{errors: window.reportErrors, traces: traces}});
  }}, 0);
}});
</script>
</body></html>
"""


def render_page(run, figures, plotlyjs, thumbs):
    sections = []
    for name, title, figure in figures:
        sections.append("<h2>%s</h2>\n%s" % (html.escape(title), plot_div(name, figure)))
    if thumbs:
        images = "".join('<figure><img src="data:image/png;base64,%s" alt="%s">'
                         "<figcaption>%s</figcaption></figure>"
                         % (data, html.escape(name), html.escape(name)) for name, data in thumbs)
        sections.append('<h2>Overlays (final curves on each keyframe)</h2>\n'
                        '<div class="thumbs">%s</div>' % images)
    notes = "".join('<p class="note">%s</p>' % html.escape(note) for note in run["notes"])
    return PAGE.format(title=html.escape("curvesfm run: %s" % os.path.abspath(run["dir"])),
                       summary=summary_table(run), notes=notes, sections="\n".join(sections),
                       plotlyjs=plotlyjs)


def plot_div(name, figure):
    """A div that plotly.js fills with `figure` (plotly 5.4's to_html cannot name the div)."""
    # "</" inside a script element would end it early.
    spec = figure.to_json().replace("</", "<\\/")
    return ('<div id="%s" class="plotly-graph-div"></div>\n<script>\n(function () {\n'
            "  var figure = %s;\n"
            '  Plotly.newPlot("%s", figure.data, figure.layout, {displaylogo: false});\n'
            "})();\n</script>" % (name, spec, name))


def summary_table(run):
    report = run["report"]
    counts = report.get("counts", {})
    ate = report.get("ate", {})
    rows = [("dataset", report.get("dataset", {}).get("dir", "?"))]
    rows += [(key, counts[key]) for key in ("frames", "keyframes", "curves", "segments")
             if key in counts]
    for which in ("initial", "refined"):
        stats = ate.get("%s_m" % which)
        if stats:
            rows.append(("ATE rmse, %s (m)" % which, "%.6g" % stats["rmse"]))
    if "total_seconds" in report:
        rows.append(("total time (s)", "%.1f" % report["total_seconds"]))
    return "<table>%s</table>" % "".join(
        "<tr><th>%s</th><td>%s</td></tr>" % (html.escape(str(k)), html.escape(str(v)))
        for k, v in rows)

