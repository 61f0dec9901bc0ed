#pragma once

#include <map>
#include <nlohmann/json.hpp>
#include <string>

#include "core/trajectory_evaluation.h"
#include "factors/curve_reprojection_factor.h"
#include "graph/optimizer.h"
#include "graph/scheduler.h"

namespace curvesfm {

// The pieces of the commands' report.json files that several commands share.

/// The program's version and the git commit it was built from, as {"version": "0.1.0",
/// "commit": "abc1234"}: the version is CMake's project(VERSION), the commit
/// `git rev-parse --short HEAD` of the source tree when it was last built ("unknown" outside a
/// git checkout, e.g. a tarball). `curvesfm --version` prints both; report.json holds this
/// object under "curvesfm".
nlohmann::json versionJson();

/// An OptimizationSummary as a JSON object (for report.json).
nlohmann::json summaryToJson(const OptimizationSummary& summary);

/// Costs per factor type as {type: {count, cost}} (for report.json).
nlohmann::json costsToJson(const std::map<std::string, FactorTypeCost>& costs);

/// A ScheduleReport as a JSON object: totals, stop reason, warnings and every phase with its
/// solver summary (for report.json).
nlohmann::json scheduleReportToJson(const ScheduleReport& report);

/// Where curve samples fall (CurveSampleCounts) as a JSON object with a total.
nlohmann::json sampleCountsToJson(const CurveSampleCounts& counts);

/// The matched poses of `evaluation` in match order, as {"timestamp": [...] (the estimate's, s),
/// "error_m": [...] (ATE), "aligned_position": [[x, y, z], ...] (the aligned estimated camera
/// centre), "ground_truth_position": [[x, y, z], ...]} in the ground truth's world (m), so that
/// figures draw the alignment without computing it again.
nlohmann::json matchedPosesToJson(const TrajectoryEvaluation& evaluation);

/// ErrorStatistics as {count, rmse, mean, median, std, min, max}.
nlohmann::json statisticsToJson(const ErrorStatistics& statistics);

/// The alignment of `evaluation` (ground_truth_from_estimate) as {kind, maps, scale, rotation
/// (3x3 rows), rotation_angle_deg, translation_m}.
nlohmann::json alignmentToJson(const TrajectoryEvaluation& evaluation);

/// Writes `json` (indented) to `path`; IoError naming the path if it cannot.
void writeJsonFile(const std::string& path, const nlohmann::json& json);

}  // namespace curvesfm
