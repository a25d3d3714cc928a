#pragma once
/// \file
/// Renderings of an analysis: the `--summary` text, its JSON form and the
/// per-node CSV rows. Not realtime-safe.

#include <string_view>

#include <fmt/format.h>

#include "fieldbus/trace/analyzer.hpp"

namespace canmotion::trace {

/// Settings for the report.
struct ReportOptions {
  int time_digits = 6;
  bool has_time = true;
};

/// Append the human-readable summary of one bus.
void format_summary_text(std::string_view iface, const Analyzer& a, const ReportOptions& opt, fmt::memory_buffer& out);

/// Append the summary of one bus as a JSON object (no trailing newline).
void format_summary_json(std::string_view iface, const Analyzer& a, const ReportOptions& opt, fmt::memory_buffer& out);

/// CSV header for per-node files; with `units` two more columns in user units.
void format_csv_header(bool units, fmt::memory_buffer& out);

/// One CSV row for a sample; `counts_per_unit` > 0 adds the user-unit columns.
void format_csv_row(const Sample& s, const ReportOptions& opt, double counts_per_unit, fmt::memory_buffer& out);

}  // namespace canmotion::trace
