#pragma once
// gnuplot rendering for cantrace --plot (tool-side I/O: writes a script and runs gnuplot).

#include <cstdint>
#include <string>
#include <vector>

#include "fieldbus/trace/analyzer.hpp"
#include "fieldbus/trace/report.hpp"

/// One node's CSV file (written by cantrace) to plot.
struct PlotSeries {
  std::string iface;
  std::uint8_t node = 0;
  std::string axis;
  std::string csv;
  double counts_per_unit = 0;
  std::string unit;
};

/// Most nodes drawn in one picture (two panels each); more are left out with a note.
inline constexpr std::size_t kMaxPlotNodes = 6;

/// Write `dir`/cantrace-plot.gp (+ jitter data) and run gnuplot to produce
/// `out` (.png or .svg). `jitter` may be null. Returns false with `err` set on failure.
bool draw_plot(const std::string& out, const std::vector<PlotSeries>& series, const canmotion::trace::Analyzer* jitter,
               const std::string& jitter_iface, const canmotion::trace::ReportOptions& ro, const std::string& dir,
               std::string& err);
