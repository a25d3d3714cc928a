// The `--summary` text of one bus: one method per section, in the order of
// the output (bus header, SYNC and its jitter histogram, frames per cycle,
// bus load, error frames, then per node: NMT states, CiA 402 timeline, EMCY,
// SDO aborts, missing TPDOs, following error).
#include <algorithm>
#include <cmath>

#include "fieldbus/canopen/object_names.hpp"
#include "fieldbus/canopen/sdo_abort.hpp"
#include "fieldbus/trace/format.hpp"
#include "fieldbus/trace/report.hpp"
#include "fieldbus/trace/report_detail.hpp"

namespace canmotion::trace {
namespace {

namespace co = canmotion::canopen;
using detail::Out;
using detail::put;
using detail::us;

class TextSummary : detail::Summary {
 public:
  TextSummary(const Analyzer& a, const ReportOptions& opt, Out& out) : Summary(a, opt, out), t0_(a.bus().t_first) {}

  void render(std::string_view iface) {
    header(iface);
    sync();
    frames_per_cycle();
    bus_load();
    error_frames();
    for (std::uint8_t n = 1; n <= kMaxNode; ++n) {
      if (a_.node(n).seen) node(n);
    }
  }

 private:
  /// "1700000000.000100 (+0.000100)", or "-" without timestamps.
  void time_at(std::int64_t t) {
    if (!opt_.has_time) {
      put(out_, "-");
      return;
    }
    append_time(out_, t, opt_.time_digits);
    put(out_, " (+");
    append_time(out_, t - t0_, opt_.time_digits);
    put(out_, ")");
  }

  /// A list entry's start: indent and time.
  void entry(std::int64_t t) {
    put(out_, "    ");
    time_at(t);
  }

  void more_not_listed(std::uint64_t n) { print("    ... {} more not listed\n", n); }

  void header(std::string_view iface) {
    print("=== bus {} ===\n", iface);
    print("frames: {}", b_.frames);
    if (opt_.has_time && b_.frames != 0) {
      print(" in {:.6f} s (", static_cast<double>(b_.t_last - b_.t_first) / 1e9);
      append_time(out_, b_.t_first, opt_.time_digits);
      put(out_, " .. ");
      append_time(out_, b_.t_last, opt_.time_digits);
      put(out_, ")");
    }
    put(out_, "\n  by kind:");
    for (std::size_t k = 0; k < b_.kind_counts.size(); ++k) {
      if (b_.kind_counts[k] != 0) print(" {} {},", detail::kind_label(k), b_.kind_counts[k]);
    }
    if (out_.size() != 0 && out_[out_.size() - 1] == ',') out_.resize(out_.size() - 1);
    put(out_, "\n");
    if (b_.problems != 0) print("  frames with protocol problems (marked !! in the decode): {}\n", b_.problems);
  }

  void sync() {
    print("SYNC: {} frames", b_.syncs);
    if (!opt_.has_time) {
      put(out_, " (no timestamps: timing statistics unavailable)\n");
      return;
    }
    if (b_.period_ns.n == 0) {
      put(out_, "\n");
      return;
    }
    print("\n  period: mean {:.1f} us, min {:.1f} us, max {:.1f} us, stddev {:.1f} us ({} periods)\n",
          us(b_.period_ns.mean), us(b_.period_ns.min), us(b_.period_ns.max), us(b_.period_ns.stddev()), b_.period_ns.n);
    print("  nominal period {:.1f} us ({}); jitter = period - nominal, histogram bin {:.1f} us:\n",
          us(static_cast<double>(b_.nominal_period_ns)), b_.nominal_source, us(static_cast<double>(b_.jitter.bin_width_ns)));
    jitter_histogram();
  }

  /// The bins from the first to the last non-empty one, and the counts below and above them.
  void jitter_histogram() {
    const JitterHistogram& h = b_.jitter;
    std::uint64_t peak = std::max(h.below, h.above);
    std::size_t lo = h.kBins, hi = 0;
    for (std::size_t i = 0; i < h.kBins; ++i) {
      peak = std::max(peak, h.bins[i]);
      if (h.bins[i] != 0) {
        lo = std::min(lo, i);
        hi = i;
      }
    }
    const auto row_end = [&](std::uint64_t c) {
      const auto n = peak == 0 ? 0 : static_cast<std::size_t>(std::ceil(40.0 * static_cast<double>(c) / static_cast<double>(peak)));
      for (std::size_t i = 0; i < n; ++i) out_.push_back('#');
      put(out_, "\n");
    };
    if (h.below != 0) {
      print("    {:>10} us {:>9} |", fmt::format("< {:.1f}", us(h.lower_edge_ns(0))), h.below);
      row_end(h.below);
    }
    for (std::size_t i = lo; i <= hi && lo < h.kBins; ++i) {
      const double centre = us(static_cast<double>((static_cast<std::int64_t>(i) - JitterHistogram::kHalfBins) * h.bin_width_ns));
      print("    {:>+10.1f} us {:>9} |", centre, h.bins[i]);
      row_end(h.bins[i]);
    }
    if (h.above != 0) {
      print("    {:>10} us {:>9} |", fmt::format("> {:.1f}", us(h.lower_edge_ns(h.kBins))), h.above);
      row_end(h.above);
    }
  }

  void frames_per_cycle() {
    const RunningStats& st = b_.frames_per_cycle_stats;
    if (st.n == 0) return;
    print("frames per SYNC cycle: mean {:.2f}, min {:.0f}, max {:.0f};", st.mean, st.min, st.max);
    for (std::size_t i = 0; i < b_.frames_per_cycle.size(); ++i) {
      if (b_.frames_per_cycle[i] != 0) print(" {}{}:{}", i, i + 1 == b_.frames_per_cycle.size() ? "+" : "", b_.frames_per_cycle[i]);
    }
    put(out_, " (frames:cycles)\n");
  }

  void bus_load() {
    if (!opt_.has_time || b_.load.empty()) return;
    print("bus load at {:.0f} kbit/s (worst-case bit stuffing): mean {:.1f} %, peak {:.1f} %; per {:.0f} ms window:\n",
          ao_.bitrate / 1000.0, 100.0 * b_.load_mean, 100.0 * b_.load_peak, static_cast<double>(b_.load_window_ns) / 1e6);
    // At most 40 rows: group windows when there are more.
    const std::size_t group = (b_.load.size() + 39) / 40;
    for (std::size_t i = 0; i < b_.load.size(); i += group) {
      double m = 0;
      for (std::size_t k = i; k < std::min(b_.load.size(), i + group); ++k) m = std::max(m, b_.load[k]);
      print("    +{:>9.3f} s {:>6.1f} % |", static_cast<double>(i) * static_cast<double>(b_.load_window_ns) / 1e9, 100.0 * m);
      const auto bars = static_cast<std::size_t>(std::lround(std::min(1.0, m) * 50.0));
      for (std::size_t k = 0; k < bars; ++k) out_.push_back('#');
      put(out_, "\n");
    }
    if (group > 1) print("    (each row: peak of {} windows)\n", group);
  }

  void error_frames() {
    print("error frames: {}", b_.error_frames);
    if (b_.error_frames == 0) {
      put(out_, "\n");
      return;
    }
    put(out_, " (");
    bool first = true;
    for (unsigned k = 0; k < b_.error_class_counts.size(); ++k) {
      if (b_.error_class_counts[k] == 0) continue;
      if (!first) put(out_, ", ");
      first = false;
      const std::string_view n = error_class_name(k);
      print("{} {}", n.empty() ? "class" : n, b_.error_class_counts[k]);
    }
    put(out_, ")\n");
    for (const ErrorFrameRecord& e : b_.error_list) {
      entry(e.t_ns);
      put(out_, "  ");
      append_error_details(out_, e.classes, e.data, 8);
      put(out_, "\n");
    }
    if (b_.error_list.size() < b_.error_frames) more_not_listed(b_.error_frames - b_.error_list.size());
  }

  void node(std::uint8_t n) {
    const NodeSummary& ns = a_.node(n);
    const NodeSettings& s = ao_.nodes[n];
    print("\n--- node {}", n);
    if (!s.name.empty()) print(" ({})", s.name);
    print(" ---\nframes: {} (TPDO {}, RPDO {}, SDO {} requests / {} responses, heartbeats {}, EMCY {})\n", ns.frames,
          ns.tpdos, ns.rpdos, ns.sdo_requests, ns.sdo_responses, ns.heartbeats, ns.emcy_count);
    nmt_states(ns);
    state_timeline(ns);
    emcys(ns);
    sdo_aborts(ns);
    missing_tpdos(ns);
    following_error(ns, s);
  }

  void nmt_states(const NodeSummary& ns) {
    if (ns.nmt.empty()) return;
    put(out_, "NMT states:\n");
    for (const NmtChange& c : ns.nmt) {
      entry(c.t_ns);
      print("  {}\n", co::nmt_state_name(c.state));
    }
    if (ns.nmt_dropped != 0) more_not_listed(ns.nmt_dropped);
  }

  void state_timeline(const NodeSummary& ns) {
    if (ns.timeline.empty()) return;
    put(out_, "CiA 402 state timeline:\n");
    for (const StateChange& c : ns.timeline) {
      entry(c.t_ns);
      print("  {:<24} statusword 0x{:04X}", cia402::state_name(c.state), c.statusword);
      if (c.has_controlword) print("  (last controlword 0x{:04X} {})", c.controlword, controlword_command_name(c.controlword));
      put(out_, "\n");
    }
    if (ns.timeline_dropped != 0) more_not_listed(ns.timeline_dropped);
  }

  void emcys(const NodeSummary& ns) {
    print("EMCY: {}\n", ns.emcy_count);
    for (const EmcyRecord& e : ns.emcys) {
      entry(e.t_ns);
      put(out_, "  ");
      append_emcy(out_, e.code, e.error_register);
      put(out_, "\n");
    }
    if (ns.emcys.size() < ns.emcy_count) more_not_listed(ns.emcy_count - ns.emcys.size());
  }

  void sdo_aborts(const NodeSummary& ns) {
    if (ns.abort_count == 0) return;
    print("SDO aborts: {}\n", ns.abort_count);
    for (const AbortRecord& r : ns.aborts) {
      entry(r.t_ns);
      const std::string_view name = co::object_name(r.index, r.sub);
      print("  0x{:04X}:{:02X}{}{}: 0x{:08X} {} ({})\n", r.index, r.sub, name.empty() ? "" : " ", name, r.code,
            co::sdo_abort_text(r.code), r.by_server ? "by drive" : "by master");
    }
  }

  void missing_tpdos(const NodeSummary& ns) {
    print("SYNC cycles without TPDO: {} of {} checked", ns.missing_tpdo, ns.syncs_checked);
    if (ns.late_tpdo != 0) print(" ({} more TPDOs came late, in the next cycle)", ns.late_tpdo);
    put(out_, "\n");
    for (std::size_t i = 0; i < ns.missing_times.size() && i < 10; ++i) {
      put(out_, "    after SYNC at ");
      time_at(ns.missing_times[i]);
      put(out_, "\n");
    }
    if (ns.missing_tpdo > 10) more_not_listed(ns.missing_tpdo - 10);
  }

  void following_error(const NodeSummary& ns, const NodeSettings& s) {
    if (ns.ferr_count == 0) {
      put(out_, "following error: no samples in Operation enabled with a target\n");
      return;
    }
    if (ao_.ferr_lag_cycles == 0) {
      put(out_, "following error (target applied at SYNC - actual");
    } else {
      print("following error (target applied {} SYNC(s) earlier - actual", ao_.ferr_lag_cycles);
    }
    print(", {} samples in Operation enabled): max |e| {} counts", ns.ferr_count, ns.ferr_max_abs);
    if (opt_.has_time) {
      put(out_, " at ");
      time_at(ns.ferr_t_max);
    }
    print(", RMS {:.2f} counts", ns.ferr_rms());
    if (s.counts_per_unit > 0) {
      const std::string_view unit = s.unit.empty() ? std::string_view("units") : std::string_view(s.unit);
      print("; max {:.6g} {}, RMS {:.6g} {}", static_cast<double>(ns.ferr_max_abs) / s.counts_per_unit, unit,
            ns.ferr_rms() / s.counts_per_unit, unit);
    }
    put(out_, "\n");
    const std::size_t best = ns.best_lag();
    if (best < NodeSummary::kLagFit && best != ao_.ferr_lag_cycles && ns.lag_rms(best) < ns.ferr_rms()) {
      print("  note: the actual position matches the target applied {} SYNC(s) earlier better "
            "(max |e| {} counts, RMS {:.2f} counts): try --lag {}\n",
            best, ns.lag_max_abs[best], ns.lag_rms(best), best);
    }
  }

  std::int64_t t0_;
};

}  // namespace

void format_summary_text(std::string_view iface, const Analyzer& a, const ReportOptions& opt, Out& out) {
  TextSummary(a, opt, out).render(iface);
}

}  // namespace canmotion::trace
