#pragma once

namespace curvesfm {

/// The process's peak resident set so far (MiB): getrusage's ru_maxrss, what `/usr/bin/time -v`
/// reports as "Maximum resident set size". -1 where the platform does not say.
double peakResidentMiB();

}  // namespace curvesfm
