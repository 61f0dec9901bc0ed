#pragma once

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "frontend/mapping/pipeline.h"

namespace curvesfm {

/// Adds one flag per PipelineOptions field to `command`, named by stage: `--undistort-*`,
/// `--edges-*`, `--chains-*`, `--field-*`, `--depth-*`, `--init-*` (curve initialiser),
/// `--match-*`, `--map-*`, `--ba-*`, `--local-ba-*`, `--global-ba-*`, `--track-*` and a few
/// pipeline-wide ones (`--reassociation-rounds`, ...). Defaults are those of `*options`, which
/// must outlive the parse. `curvesfm run` and planar_bench share them, so a --config file works
/// for both.
void addPipelineFlags(CLI::App* command, PipelineOptions* options);

/// Every field of every stage, enums by name, grouped as {"edges": {...}, "local_ba":
/// {"optimizer": {...}}, ...}: the same table as addPipelineFlags, so the two cannot drift apart.
nlohmann::json pipelineOptionsToJson(PipelineOptions options);

}  // namespace curvesfm
