"""matplotlib, off-screen, and the helpers the figures share."""
import os

from .inputs import InputError

try:
    import matplotlib

    matplotlib.use("Agg")  # No display: the figures go to files.
    import matplotlib.pyplot as plt
except ImportError:
    raise InputError("matplotlib is missing (Debian: apt-get install python3-matplotlib)")

GREY = "0.55"


def save(figure, *paths):
    """Writes `figure` to each path (the extension picks PNG or PDF), then closes it."""
    try:
        for path in paths:
            try:
                figure.savefig(path, dpi=100)
            except OSError as e:
                raise InputError("%s: cannot write: %s" % (path, e.strerror))
    finally:
        plt.close(figure)
    return paths


def save_png_and_pdf(figure, out_dir, name):
    """Writes OUT_DIR/NAME.png and OUT_DIR/NAME.pdf."""
    return save(figure, *(os.path.join(out_dir, name + ext) for ext in (".png", ".pdf")))


def label_bars(axes, bars):
    """The value above each bar, as the charts of the benches show them."""
    for bar in bars:
        height = bar.get_height()
        if height == height:  # NaN bars (no such run) get no label.
            axes.annotate("%.3g" % height, (bar.get_x() + bar.get_width() / 2, height),
                          ha="center", va="bottom", fontsize=8)
