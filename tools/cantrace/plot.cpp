#include "plot.hpp"

#include <fmt/format.h>
#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>

namespace tr = canmotion::trace;

namespace {

// gnuplot single-quoted string: double any single quote.
std::string q(const std::string& s) {
  std::string r = "'";
  for (char c : s) {
    if (c == '\'') r += "''";
    else r += c;
  }
  return r + "'";
}

// Escape gnuplot enhanced-text specials in titles.
std::string esc(const std::string& s) {
  std::string r;
  for (char c : s) {
    if (c == '_' || c == '^' || c == '@' || c == '&' || c == '{' || c == '}') r += '\\';
    r += c;
  }
  return r;
}

}  // namespace

bool draw_plot(const std::string& out, const std::vector<PlotSeries>& all, const tr::Analyzer* jitter,
               const std::string& jitter_iface, const tr::ReportOptions& ro, const std::string& dir, std::string& err) {
  const bool svg = out.ends_with(".svg");
  std::vector<PlotSeries> series(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(std::min(all.size(), kMaxPlotNodes)));
  const bool have_jitter = jitter != nullptr && ro.has_time && jitter->bus().period_ns.n != 0;
  if (series.empty() && !have_jitter) {
    err = "nothing to plot: no TPDOs with statusword/position and no SYNC periods in the trace";
    return false;
  }
  const double t0 = jitter != nullptr ? static_cast<double>(jitter->bus().t_first) / 1e9 : 0.0;
  const std::string jitter_dat = dir + "/cantrace-jitter.dat";
  if (have_jitter) {
    std::FILE* f = std::fopen(jitter_dat.c_str(), "w");
    if (f == nullptr) {
      err = "cannot write " + jitter_dat;
      return false;
    }
    const tr::JitterHistogram& h = jitter->bus().jitter;
    std::fprintf(f, "# period - nominal [us], SYNC periods\n");
    for (std::size_t i = 0; i < h.kBins; ++i) {
      const double centre = static_cast<double>((static_cast<std::int64_t>(i) - tr::JitterHistogram::kHalfBins) * h.bin_width_ns) / 1000.0;
      std::fprintf(f, "%.3f %llu\n", centre, static_cast<unsigned long long>(h.bins[i]));
    }
    std::fclose(f);
  }
  const int rows = static_cast<int>(2 * series.size()) + (have_jitter ? 1 : 0);
  const int height = 260 * rows + 60;
  std::string g;
  if (svg) {
    g += fmt::format("set terminal svg size 1200,{} dynamic enhanced font 'DejaVu Sans,11' background rgb 'white'\n", height);
  } else {
    g += fmt::format("set terminal pngcairo size 1400,{} enhanced font 'DejaVu Sans,10' background rgb 'white'\n", height);
  }
  g += "set output " + q(out) + "\n";
  g += "set datafile separator ','\nset datafile missing ''\n";
  g += "set grid xtics ytics lc rgb '#dddddd'\nset border lw 1\nset lmargin 12\nset rmargin 3\nset key at graph 1, graph 1.02 right bottom horizontal nobox\n";
  // One time axis for every time panel, so they line up.
  if (jitter != nullptr && jitter->bus().t_last > jitter->bus().t_first) {
    g += fmt::format("set xrange [0:{:.9f}]\n", static_cast<double>(jitter->bus().t_last - jitter->bus().t_first) / 1e9);
  }
  g += "set format y '%.6g'\n";
  g += fmt::format("set multiplot layout {},1 title 'cantrace: positions, following error and SYNC jitter' font ',13'\n", rows);
  for (const PlotSeries& s : series) {
    const bool units = s.counts_per_unit > 0;
    const std::string unit = units ? (s.unit.empty() ? "units" : s.unit) : "counts";
    const int tcol = units ? 8 : 5, acol = units ? 9 : 6, ecol = units ? 10 : 7;
    const std::string who = esc(fmt::format("{} node {}{}", s.iface, s.node, s.axis.empty() ? "" : " (" + s.axis + ")"));
    g += fmt::format("set title '{}: target vs actual position'\n", who);
    g += "set xlabel 'time since start of trace [s]'\n";
    g += fmt::format("set ylabel 'position [{}]'\n", esc(unit));
    g += fmt::format(
        "plot {0} skip 1 using ($1-{1:.9f}):{2} with lines lw 2 lc rgb '#1f77b4' title 'target (applied at SYNC)', \\\n"
        "     {0} skip 1 using ($1-{1:.9f}):{3} with lines lw 1.5 dt 2 lc rgb '#d62728' title 'actual (TPDO)'\n",
        q(s.csv), t0, tcol, acol);
    g += fmt::format("set title '{}: following error (Operation enabled only)'\n", who);
    g += fmt::format("set ylabel 'following error [{}]'\n", esc(unit));
    g += fmt::format("plot {0} skip 1 using ($1-{1:.9f}):{2} with lines lw 1.5 lc rgb '#2ca02c' title 'target - actual'\n",
                     q(s.csv), t0, ecol);
  }
  if (have_jitter) {
    const tr::BusSummary& b = jitter->bus();
    g += fmt::format("set title '{}'\n",
                     esc(fmt::format("{}: SYNC period jitter ({} periods, nominal {:.1f} us from {}, {} outside the range)",
                                     jitter_iface, b.period_ns.n, static_cast<double>(b.nominal_period_ns) / 1000.0,
                                     b.nominal_source, b.jitter.below + b.jitter.above)));
    g += "set xlabel 'SYNC period - nominal period [us]'\nset ylabel 'SYNC periods'\nset xrange [*:*]\n";
    g += "set datafile separator whitespace\nset style fill solid 0.6 border -1\nset yrange [0:*]\n";
    g += fmt::format("set boxwidth {:.3f}\n", static_cast<double>(b.jitter.bin_width_ns) / 1000.0 * 0.9);
    g += fmt::format("plot {} using 1:2 with boxes lc rgb '#9467bd' title 'periods per bin'\n", q(jitter_dat));
  }
  g += "unset multiplot\n";
  const std::string script = dir + "/cantrace-plot.gp";
  std::FILE* f = std::fopen(script.c_str(), "w");
  if (f == nullptr) {
    err = "cannot write " + script;
    return false;
  }
  std::fwrite(g.data(), 1, g.size(), f);
  std::fclose(f);
  const std::string cmd = "gnuplot " + q(script) + " 2>&1";
  std::FILE* p = ::popen(cmd.c_str(), "r");
  if (p == nullptr) {
    err = "cannot run gnuplot (install gnuplot-nox)";
    return false;
  }
  std::string msgs;
  char buf[512];
  while (std::fgets(buf, sizeof buf, p) != nullptr) msgs += buf;
  const int st = ::pclose(p);
  if (st != 0) {
    err = "gnuplot failed (script " + script + "):\n" + msgs;
    return false;
  }
  if (all.size() > series.size()) {
    std::fprintf(stderr, "cantrace: --plot: %zu nodes, the first %zu drawn\n", all.size(), series.size());
  }
  return true;
}
