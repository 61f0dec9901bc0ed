#pragma once

#include <string>
#include <vector>

namespace curvesfm {

// The C++ programs write data (CSV, JSON, PLY, TUM); the figures and the HTML report are drawn by
// the Python package scripts/curvesfm_plots (matplotlib, plotly). These helpers run it as
// `<python> -m curvesfm_plots <arguments>` with PYTHONPATH set to the repository's scripts folder,
// both fixed at configure time (apps/cli/CMakeLists.txt: CURVESFM_PYTHON, CURVESFM_SCRIPTS_DIR).

/// The command line that runs the package with `arguments`, shell-quoted, for messages that tell
/// the user how to draw the figures by hand.
std::string plotCommandLine(const std::vector<std::string>& arguments);

/// True if the Python interpreter starts and imports numpy and matplotlib (silently).
bool plotPackageUsable();

/// Runs the package with `arguments` (its output goes to ours) and waits for it. Returns its exit
/// code; 127 if the interpreter could not be started, -1 if it was killed.
int runPlotPackage(const std::vector<std::string>& arguments);

/// runPlotPackage(), and on a non-zero exit throws Error("<what>: <command line> failed (exit
/// code N)"): its own message is already on stderr above that line.
void runPlotPackageOrThrow(const std::string& what, const std::vector<std::string>& arguments);

/// For programs whose figures are extras beside data already written (the benches): runs the
/// package if plotPackageUsable(), else prints one line with plotCommandLine() to run later.
/// Never throws; returns true if the figures were drawn.
bool drawFiguresIfPossible(const std::vector<std::string>& arguments);

}  // namespace curvesfm
