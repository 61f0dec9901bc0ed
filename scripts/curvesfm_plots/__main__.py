"""python3 -m curvesfm_plots <sub-command> ...: see __init__.py and each sub-command's --help.

Exit codes as curvesfm's: 0 done, 1 a missing or malformed input (one line naming the file) or a
missing dependency, 2 a usage error.
"""
import argparse
import sys

from .inputs import InputError, UsageError, require_extension


def eval_command(args):
    require_extension(args.out, (".png", ".pdf"), "OUT")
    from . import eval_figure
    eval_figure.draw(args.eval_json, args.out)
    print("plot: %s" % args.out)


def report_command(args):
    from . import report
    path, traces = report.build(args.run_dir, args.out)
    print("report: %s (%s)" % (path, ", ".join("%s %d traces" % kv for kv in traces.items())))


def bench_command(draw):
    def run(args):
        from . import bench_figures
        for path in getattr(bench_figures, draw)(args.out_dir):
            print("figure: %s" % path)
    return run


def real_bench_command(args):
    from . import real_bench
    for path in real_bench.draw(args.out_dir):
        print("figure: %s" % path)


def parser():
    p = argparse.ArgumentParser(prog="python3 -m curvesfm_plots",
                                description="Figures and reports from the data curvesfm writes.")
    commands = p.add_subparsers(dest="command", required=True)
    c = commands.add_parser("report", help="interactive HTML report of a `curvesfm run` folder")
    c.add_argument("run_dir", help="output folder of curvesfm run (report.json, curves.obj, ...)")
    c.add_argument("--out", help="HTML file to write (default RUN_DIR/report.html)")
    c.set_defaults(run=report_command)
    c = commands.add_parser("eval", help="the figure of `curvesfm eval --plot`")
    c.add_argument("eval_json", help="JSON written by curvesfm eval --json")
    c.add_argument("out", help="figure to write: .png or .pdf")
    c.set_defaults(run=eval_command)
    for name, draw in (("planar-bench", "planar"), ("strategy-bench", "strategy")):
        c = commands.add_parser(name, help="figures of %s from its CSV files"
                                % name.replace("-", "_"))
        c.add_argument("out_dir", help="the bench's --out folder")
        c.set_defaults(run=bench_command(draw))
    c = commands.add_parser("real-bench", help="figures of real_bench from its CSV and "
                            "trajectories")
    c.add_argument("out_dir", help="the bench's --out folder")
    c.set_defaults(run=real_bench_command)
    return p


def main(argv=None):
    args = parser().parse_args(argv)  # Exits 2 on a usage error, with argparse's message.
    try:
        args.run(args)
    except UsageError as e:
        print("curvesfm_plots %s: %s" % (args.command, e), file=sys.stderr)
        return 2
    except InputError as e:
        print("curvesfm_plots %s: %s" % (args.command, e), file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
