#pragma once
/// A self-contained HTML report (inline SVG and CSS, images as data URIs; no network): the
/// comparison table, simulated against measured with error bars, the failing observables
/// highlighted, the residual pattern (z by rig and setting), chi2/dof along a chain of model
/// versions, the diagnosis, and the rig pictures.
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "clumpkit/calibrate/comparison.hpp"
#include "clumpkit/calibrate/diagnosis.hpp"

namespace clumpkit::calibrate {

struct ReportInput {
  std::string title = "clumpkit: model against measurements";
  /// Model versions in order (name, comparison); the last is shown in detail.
  std::vector<std::pair<std::string, Comparison>> chain;
  const Diagnosis* diagnosis = nullptr;
  std::vector<std::filesystem::path> pictures;  ///< PNG files embedded as they are
};

std::string report_html(const ReportInput& in);

/// Writes `dir/index.html` (atomically; the folder is created).
void write_report(const ReportInput& in, const std::filesystem::path& dir);

}  // namespace clumpkit::calibrate
