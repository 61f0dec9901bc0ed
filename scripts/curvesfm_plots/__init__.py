"""Figures and reports of curvesfm, drawn from the data its programs write.

The C++ programs write data only (CSV, JSON, PLY/OBJ, TUM trajectories); this package draws it:
matplotlib figures (PNG and PDF) for `curvesfm eval --plot` and the benches, and a self-contained
interactive HTML report (plotly) of one `curvesfm run` folder. Run it as

    PYTHONPATH=<repo>/scripts python3 -m curvesfm_plots <sub-command> ...

Needs numpy and matplotlib (and plotly for `report`): Debian python3-numpy, python3-matplotlib,
python3-plotly, which scripts/install-deps.sh installs.
"""
