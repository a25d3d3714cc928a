#include "fieldbus/trace/report.hpp"

#include <algorithm>
#include <cmath>

#include "fieldbus/canopen/emcy.hpp"
#include "fieldbus/canopen/object_names.hpp"
#include "fieldbus/canopen/sdo_abort.hpp"
#include "fieldbus/trace/format.hpp"

namespace canmotion::trace {
namespace {

namespace co = canmotion::canopen;

using Out = fmt::memory_buffer;

void put(Out& out, std::string_view s) { out.append(s.data(), s.data() + s.size()); }

void time_at(Out& out, const ReportOptions& opt, std::int64_t t, std::int64_t t0) {
  if (!opt.has_time) {
    put(out, "-");
    return;
  }
  append_time(out, t, opt.time_digits);
  put(out, " (+");
  append_time(out, t - t0, opt.time_digits);
  put(out, ")");
}

std::string_view kind_label(std::size_t k) {
  constexpr std::array<std::string_view, 12> names = {"NMT",       "SYNC", "TIME", "EMCY", "boot-up", "heartbeat",
                                                      "node guard", "SDO",  "PDO",  "LSS",  "error",   "unknown"};
  return k < names.size() ? names[k] : "?";
}

double us(double ns) { return ns / 1000.0; }

void node_label(Out& out, std::uint8_t n, const NodeSettings& s) {
  fmt::format_to(fmt::appender(out), "node {}", n);
  if (!s.name.empty()) fmt::format_to(fmt::appender(out), " ({})", s.name);
}

}  // namespace

void format_summary_text(std::string_view iface, const Analyzer& a, const ReportOptions& opt, Out& out) {
  const BusSummary& b = a.bus();
  const AnalyzerOptions& ao = a.options();
  const std::int64_t t0 = b.t_first;
  fmt::format_to(fmt::appender(out), "=== bus {} ===\n", iface);
  fmt::format_to(fmt::appender(out), "frames: {}", b.frames);
  if (opt.has_time && b.frames != 0) {
    fmt::format_to(fmt::appender(out), " in {:.6f} s (", static_cast<double>(b.t_last - b.t_first) / 1e9);
    append_time(out, b.t_first, opt.time_digits);
    put(out, " .. ");
    append_time(out, b.t_last, opt.time_digits);
    put(out, ")");
  }
  put(out, "\n  by kind:");
  for (std::size_t k = 0; k < b.kind_counts.size(); ++k) {
    if (b.kind_counts[k] != 0) fmt::format_to(fmt::appender(out), " {} {},", kind_label(k), b.kind_counts[k]);
  }
  if (out.size() != 0 && out[out.size() - 1] == ',') out.resize(out.size() - 1);
  put(out, "\n");
  if (b.problems != 0) fmt::format_to(fmt::appender(out), "  frames with protocol problems (marked !! in the decode): {}\n", b.problems);

  // SYNC
  fmt::format_to(fmt::appender(out), "SYNC: {} frames", b.syncs);
  if (!opt.has_time) {
    put(out, " (no timestamps: timing statistics unavailable)\n");
  } else if (b.period_ns.n == 0) {
    put(out, "\n");
  } else {
    fmt::format_to(fmt::appender(out), "\n  period: mean {:.1f} us, min {:.1f} us, max {:.1f} us, stddev {:.1f} us ({} periods)\n",
                   us(b.period_ns.mean), us(b.period_ns.min), us(b.period_ns.max), us(b.period_ns.stddev()),
                   b.period_ns.n);
    fmt::format_to(fmt::appender(out), "  nominal period {:.1f} us ({}); jitter = period - nominal, histogram bin {:.1f} us:\n",
                   us(static_cast<double>(b.nominal_period_ns)), b.nominal_source,
                   us(static_cast<double>(b.jitter.bin_width_ns)));
    const JitterHistogram& h = b.jitter;
    std::uint64_t peak = std::max(h.below, h.above);
    std::size_t lo = h.kBins, hi = 0;
    for (std::size_t i = 0; i < h.kBins; ++i) {
      peak = std::max(peak, h.bins[i]);
      if (h.bins[i] != 0) {
        lo = std::min(lo, i);
        hi = i;
      }
    }
    auto bar = [&](std::uint64_t c) {
      const auto n = peak == 0 ? 0 : static_cast<std::size_t>(std::ceil(40.0 * static_cast<double>(c) / static_cast<double>(peak)));
      for (std::size_t i = 0; i < n; ++i) out.push_back('#');
    };
    if (h.below != 0) {
      fmt::format_to(fmt::appender(out), "    {:>10} us {:>9} |", fmt::format("< {:.1f}", us(h.lower_edge_ns(0))), h.below);
      bar(h.below);
      put(out, "\n");
    }
    for (std::size_t i = lo; i <= hi && lo < h.kBins; ++i) {
      const double centre = us(static_cast<double>((static_cast<std::int64_t>(i) - JitterHistogram::kHalfBins) * h.bin_width_ns));
      fmt::format_to(fmt::appender(out), "    {:>+10.1f} us {:>9} |", centre, h.bins[i]);
      bar(h.bins[i]);
      put(out, "\n");
    }
    if (h.above != 0) {
      fmt::format_to(fmt::appender(out), "    {:>10} us {:>9} |", fmt::format("> {:.1f}", us(h.lower_edge_ns(h.kBins))), h.above);
      bar(h.above);
      put(out, "\n");
    }
  }
  if (b.frames_per_cycle_stats.n != 0) {
    fmt::format_to(fmt::appender(out), "frames per SYNC cycle: mean {:.2f}, min {:.0f}, max {:.0f};", b.frames_per_cycle_stats.mean,
                   b.frames_per_cycle_stats.min, b.frames_per_cycle_stats.max);
    for (std::size_t i = 0; i < b.frames_per_cycle.size(); ++i) {
      if (b.frames_per_cycle[i] != 0) {
        fmt::format_to(fmt::appender(out), " {}{}:{}", i, i + 1 == b.frames_per_cycle.size() ? "+" : "", b.frames_per_cycle[i]);
      }
    }
    put(out, " (frames:cycles)\n");
  }
  if (opt.has_time && !b.load.empty()) {
    fmt::format_to(fmt::appender(out),
                   "bus load at {:.0f} kbit/s (worst-case bit stuffing): mean {:.1f} %, peak {:.1f} %; per {:.0f} ms window:\n",
                   ao.bitrate / 1000.0, 100.0 * b.load_mean, 100.0 * b.load_peak, static_cast<double>(b.load_window_ns) / 1e6);
    // At most 40 rows: group windows when there are more.
    const std::size_t group = (b.load.size() + 39) / 40;
    for (std::size_t i = 0; i < b.load.size(); i += group) {
      double m = 0;
      std::size_t n = 0;
      for (std::size_t k = i; k < std::min(b.load.size(), i + group); ++k, ++n) m = std::max(m, b.load[k]);
      fmt::format_to(fmt::appender(out), "    +{:>9.3f} s {:>6.1f} % |", static_cast<double>(i) * static_cast<double>(b.load_window_ns) / 1e9,
                     100.0 * m);
      const auto bars = static_cast<std::size_t>(std::lround(std::min(1.0, m) * 50.0));
      for (std::size_t k = 0; k < bars; ++k) out.push_back('#');
      put(out, "\n");
    }
    if (group > 1) fmt::format_to(fmt::appender(out), "    (each row: peak of {} windows)\n", group);
  }
  fmt::format_to(fmt::appender(out), "error frames: {}", b.error_frames);
  if (b.error_frames != 0) {
    put(out, " (");
    bool first = true;
    for (unsigned k = 0; k < b.error_class_counts.size(); ++k) {
      if (b.error_class_counts[k] == 0) continue;
      if (!first) put(out, ", ");
      first = false;
      const std::string_view n = error_class_name(k);
      fmt::format_to(fmt::appender(out), "{} {}", n.empty() ? "class" : n, b.error_class_counts[k]);
    }
    put(out, ")\n");
    for (const ErrorFrameRecord& e : b.error_list) {
      put(out, "    ");
      time_at(out, opt, e.t_ns, t0);
      put(out, "  ");
      append_error_details(out, e.classes, e.data, 8);
      put(out, "\n");
    }
    if (b.error_list.size() < b.error_frames) {
      fmt::format_to(fmt::appender(out), "    ... {} more not listed\n", b.error_frames - b.error_list.size());
    }
  } else {
    put(out, "\n");
  }

  for (std::uint8_t n = 1; n <= kMaxNode; ++n) {
    const NodeSummary& ns = a.node(n);
    if (!ns.seen) continue;
    const NodeSettings& s = ao.nodes[n];
    put(out, "\n--- ");
    node_label(out, n, s);
    fmt::format_to(fmt::appender(out), " ---\nframes: {} (TPDO {}, RPDO {}, SDO {} requests / {} responses, heartbeats {}, EMCY {})\n",
                   ns.frames, ns.tpdos, ns.rpdos, ns.sdo_requests, ns.sdo_responses, ns.heartbeats, ns.emcy_count);
    if (!ns.nmt.empty()) {
      put(out, "NMT states:\n");
      for (const NmtChange& c : ns.nmt) {
        put(out, "    ");
        time_at(out, opt, c.t_ns, t0);
        fmt::format_to(fmt::appender(out), "  {}\n", co::nmt_state_name(c.state));
      }
      if (ns.nmt_dropped != 0) fmt::format_to(fmt::appender(out), "    ... {} more not listed\n", ns.nmt_dropped);
    }
    if (!ns.timeline.empty()) {
      put(out, "CiA 402 state timeline:\n");
      for (const StateChange& c : ns.timeline) {
        put(out, "    ");
        time_at(out, opt, c.t_ns, t0);
        fmt::format_to(fmt::appender(out), "  {:<24} statusword 0x{:04X}", cia402::state_name(c.state), c.statusword);
        if (c.has_controlword) {
          fmt::format_to(fmt::appender(out), "  (last controlword 0x{:04X} {})", c.controlword,
                         controlword_command_name(c.controlword));
        }
        put(out, "\n");
      }
      if (ns.timeline_dropped != 0) fmt::format_to(fmt::appender(out), "    ... {} more not listed\n", ns.timeline_dropped);
    }
    fmt::format_to(fmt::appender(out), "EMCY: {}\n", ns.emcy_count);
    for (const EmcyRecord& e : ns.emcys) {
      put(out, "    ");
      time_at(out, opt, e.t_ns, t0);
      put(out, "  ");
      append_emcy(out, e.code, e.error_register);
      put(out, "\n");
    }
    if (ns.emcys.size() < ns.emcy_count) fmt::format_to(fmt::appender(out), "    ... {} more not listed\n", ns.emcy_count - ns.emcys.size());
    if (ns.abort_count != 0) {
      fmt::format_to(fmt::appender(out), "SDO aborts: {}\n", ns.abort_count);
      for (const AbortRecord& r : ns.aborts) {
        put(out, "    ");
        time_at(out, opt, r.t_ns, t0);
        const std::string_view name = co::object_name(r.index, r.sub);
        fmt::format_to(fmt::appender(out), "  0x{:04X}:{:02X}{}{}: 0x{:08X} {} ({})\n", r.index, r.sub, name.empty() ? "" : " ", name,
                       r.code, co::sdo_abort_text(r.code), r.by_server ? "by drive" : "by master");
      }
    }
    fmt::format_to(fmt::appender(out), "SYNC cycles without TPDO: {} of {} checked", ns.missing_tpdo, ns.syncs_checked);
    if (ns.late_tpdo != 0) fmt::format_to(fmt::appender(out), " ({} more TPDOs came late, in the next cycle)", ns.late_tpdo);
    put(out, "\n");
    for (std::size_t i = 0; i < ns.missing_times.size() && i < 10; ++i) {
      put(out, "    after SYNC at ");
      time_at(out, opt, ns.missing_times[i], t0);
      put(out, "\n");
    }
    if (ns.missing_tpdo > 10) fmt::format_to(fmt::appender(out), "    ... {} more not listed\n", ns.missing_tpdo - 10);
    if (ns.ferr_count == 0) {
      put(out, "following error: no samples in Operation enabled with a target\n");
    } else {
      if (ao.ferr_lag_cycles == 0) {
        put(out, "following error (target applied at SYNC - actual");
      } else {
        fmt::format_to(fmt::appender(out), "following error (target applied {} SYNC(s) earlier - actual", ao.ferr_lag_cycles);
      }
      fmt::format_to(fmt::appender(out), ", {} samples in Operation enabled): max |e| {} counts", ns.ferr_count, ns.ferr_max_abs);
      if (opt.has_time) {
        put(out, " at ");
        time_at(out, opt, ns.ferr_t_max, t0);
      }
      fmt::format_to(fmt::appender(out), ", RMS {:.2f} counts", ns.ferr_rms());
      if (s.counts_per_unit > 0) {
        fmt::format_to(fmt::appender(out), "; max {:.6g} {}, RMS {:.6g} {}", static_cast<double>(ns.ferr_max_abs) / s.counts_per_unit,
                       s.unit.empty() ? "units" : s.unit, ns.ferr_rms() / s.counts_per_unit, s.unit.empty() ? "units" : s.unit);
      }
      put(out, "\n");
      const std::size_t best = ns.best_lag();
      if (best < NodeSummary::kLagFit && best != ao.ferr_lag_cycles && ns.lag_rms(best) < ns.ferr_rms()) {
        fmt::format_to(fmt::appender(out),
                       "  note: the actual position matches the target applied {} SYNC(s) earlier better "
                       "(max |e| {} counts, RMS {:.2f} counts): try --lag {}\n",
                       best, ns.lag_max_abs[best], ns.lag_rms(best), best);
      }
    }
  }
}

void format_summary_json(std::string_view iface, const Analyzer& a, const ReportOptions& opt, Out& out) {
  const BusSummary& b = a.bus();
  const AnalyzerOptions& ao = a.options();
  auto t = [&](std::int64_t ns) {
    if (opt.has_time) {
      append_time(out, ns, opt.time_digits);
    } else {
      put(out, "null");
    }
  };
  put(out, "{\"iface\":");
  append_json_string(out, iface);
  fmt::format_to(fmt::appender(out), ",\"frames\":{},\"t_first\":", b.frames);
  t(b.t_first);
  put(out, ",\"t_last\":");
  t(b.t_last);
  put(out, ",\"kinds\":{");
  bool first = true;
  for (std::size_t k = 0; k < b.kind_counts.size(); ++k) {
    if (b.kind_counts[k] == 0) continue;
    if (!first) out.push_back(',');
    first = false;
    append_json_string(out, kind_label(k));
    fmt::format_to(fmt::appender(out), ":{}", b.kind_counts[k]);
  }
  fmt::format_to(fmt::appender(out), "}},\"problems\":{},\"sync\":{{\"count\":{}", b.problems, b.syncs);
  if (opt.has_time && b.period_ns.n != 0) {
    fmt::format_to(fmt::appender(out),
                   ",\"periods\":{},\"period_mean_us\":{:.3f},\"period_min_us\":{:.3f},\"period_max_us\":{:.3f},"
                   "\"period_stddev_us\":{:.3f},\"nominal_us\":{:.3f},\"nominal_source\":",
                   b.period_ns.n, us(b.period_ns.mean), us(b.period_ns.min), us(b.period_ns.max), us(b.period_ns.stddev()),
                   us(static_cast<double>(b.nominal_period_ns)));
    append_json_string(out, b.nominal_source);
    fmt::format_to(fmt::appender(out), ",\"jitter_histogram\":{{\"bin_us\":{:.3f},\"first_bin_centre_us\":{:.3f},\"below\":{},\"above\":{},\"bins\":[",
                   us(static_cast<double>(b.jitter.bin_width_ns)),
                   us(static_cast<double>(-JitterHistogram::kHalfBins * b.jitter.bin_width_ns)), b.jitter.below, b.jitter.above);
    for (std::size_t i = 0; i < b.jitter.bins.size(); ++i) fmt::format_to(fmt::appender(out), "{}{}", i ? "," : "", b.jitter.bins[i]);
    put(out, "]}");
  }
  put(out, "}");
  if (b.frames_per_cycle_stats.n != 0) {
    fmt::format_to(fmt::appender(out), ",\"frames_per_cycle\":{{\"mean\":{:.3f},\"min\":{:.0f},\"max\":{:.0f},\"histogram\":{{",
                   b.frames_per_cycle_stats.mean, b.frames_per_cycle_stats.min, b.frames_per_cycle_stats.max);
    first = true;
    for (std::size_t i = 0; i < b.frames_per_cycle.size(); ++i) {
      if (b.frames_per_cycle[i] == 0) continue;
      fmt::format_to(fmt::appender(out), "{}\"{}\":{}", first ? "" : ",", i, b.frames_per_cycle[i]);
      first = false;
    }
    put(out, "}}");
  }
  if (opt.has_time) {
    fmt::format_to(fmt::appender(out), ",\"bus_load\":{{\"bitrate\":{:.0f},\"window_ms\":{:.3f},\"mean\":{:.4f},\"peak\":{:.4f},\"windows\":[",
                   ao.bitrate, static_cast<double>(b.load_window_ns) / 1e6, b.load_mean, b.load_peak);
    for (std::size_t i = 0; i < b.load.size(); ++i) fmt::format_to(fmt::appender(out), "{}{:.4f}", i ? "," : "", b.load[i]);
    put(out, "]}");
  }
  fmt::format_to(fmt::appender(out), ",\"error_frames\":{{\"count\":{},\"list\":[", b.error_frames);
  for (std::size_t i = 0; i < b.error_list.size(); ++i) {
    if (i) out.push_back(',');
    put(out, "{\"t\":");
    t(b.error_list[i].t_ns);
    put(out, ",\"classes\":\"");
    append_error_details(out, b.error_list[i].classes, b.error_list[i].data, 8);
    put(out, "\"}");
  }
  put(out, "]},\"nodes\":[");
  first = true;
  for (std::uint8_t n = 1; n <= kMaxNode; ++n) {
    const NodeSummary& ns = a.node(n);
    if (!ns.seen) continue;
    if (!first) out.push_back(',');
    first = false;
    const NodeSettings& s = ao.nodes[n];
    fmt::format_to(fmt::appender(out), "{{\"node\":{},\"name\":", n);
    append_json_string(out, s.name);
    fmt::format_to(fmt::appender(out), ",\"frames\":{},\"tpdo\":{},\"rpdo\":{},\"sdo_requests\":{},\"sdo_responses\":{},\"heartbeats\":{}",
                   ns.frames, ns.tpdos, ns.rpdos, ns.sdo_requests, ns.sdo_responses, ns.heartbeats);
    put(out, ",\"nmt\":[");
    for (std::size_t i = 0; i < ns.nmt.size(); ++i) {
      put(out, i ? ",{\"t\":" : "{\"t\":");
      t(ns.nmt[i].t_ns);
      fmt::format_to(fmt::appender(out), ",\"state\":\"{}\"}}", co::nmt_state_name(ns.nmt[i].state));
    }
    put(out, "],\"states\":[");
    for (std::size_t i = 0; i < ns.timeline.size(); ++i) {
      const StateChange& c = ns.timeline[i];
      put(out, i ? ",{\"t\":" : "{\"t\":");
      t(c.t_ns);
      fmt::format_to(fmt::appender(out), ",\"state\":\"{}\",\"statusword\":{}", cia402::state_name(c.state), c.statusword);
      if (c.has_controlword) fmt::format_to(fmt::appender(out), ",\"controlword\":{}", c.controlword);
      put(out, "}");
    }
    fmt::format_to(fmt::appender(out), "],\"states_dropped\":{},\"emcy_count\":{},\"emcy\":[", ns.timeline_dropped, ns.emcy_count);
    for (std::size_t i = 0; i < ns.emcys.size(); ++i) {
      const EmcyRecord& e = ns.emcys[i];
      put(out, i ? ",{\"t\":" : "{\"t\":");
      t(e.t_ns);
      append_emcy_json(out, e.code, e.error_register);
      put(out, "}");
    }
    fmt::format_to(fmt::appender(out), "],\"sdo_abort_count\":{},\"sdo_aborts\":[", ns.abort_count);
    for (std::size_t i = 0; i < ns.aborts.size(); ++i) {
      const AbortRecord& r = ns.aborts[i];
      put(out, i ? ",{\"t\":" : "{\"t\":");
      t(r.t_ns);
      fmt::format_to(fmt::appender(out), ",\"index\":{},\"sub\":{},\"code\":{},\"text\":", r.index, r.sub, r.code);
      append_json_string(out, co::sdo_abort_text(r.code));
      put(out, "}");
    }
    fmt::format_to(fmt::appender(out), "],\"syncs_checked\":{},\"missing_tpdo\":{},\"late_tpdo\":{},\"missing_tpdo_times\":[", ns.syncs_checked,
                   ns.missing_tpdo, ns.late_tpdo);
    for (std::size_t i = 0; i < ns.missing_times.size(); ++i) {
      if (i) out.push_back(',');
      t(ns.missing_times[i]);
    }
    fmt::format_to(fmt::appender(out), "],\"following_error\":{{\"samples\":{},\"max_abs_counts\":{},\"rms_counts\":{:.3f}", ns.ferr_count,
                   ns.ferr_max_abs, ns.ferr_rms());
    if (ns.ferr_count != 0) {
      put(out, ",\"t_max\":");
      t(ns.ferr_t_max);
    }
    fmt::format_to(fmt::appender(out), ",\"lag_cycles\":{},\"lag_fit\":[", ao.ferr_lag_cycles);
    for (std::size_t l = 0; l < NodeSummary::kLagFit; ++l) {
      fmt::format_to(fmt::appender(out), "{}{{\"lag\":{},\"samples\":{},\"max_abs_counts\":{},\"rms_counts\":{:.3f}}}", l ? "," : "", l,
                     ns.lag_count[l], ns.lag_max_abs[l], ns.lag_rms(l));
    }
    put(out, "]");
    if (s.counts_per_unit > 0) {
      fmt::format_to(fmt::appender(out), ",\"unit\":");
      append_json_string(out, s.unit);
      fmt::format_to(fmt::appender(out), ",\"max_abs_units\":{:.9g},\"rms_units\":{:.9g}",
                     static_cast<double>(ns.ferr_max_abs) / s.counts_per_unit, ns.ferr_rms() / s.counts_per_unit);
    }
    put(out, "}}");
  }
  put(out, "]}");
}

void format_csv_header(bool units, Out& out) {
  put(out, "time_s,controlword,statusword,state,target_counts,actual_counts,following_error_counts");
  if (units) put(out, ",target_units,actual_units,following_error_units");
  put(out, "\n");
}

void format_csv_row(const Sample& s, const ReportOptions& opt, double counts_per_unit, Out& out) {
  append_time(out, s.t_ns, opt.time_digits);
  out.push_back(',');
  if (s.has_controlword) fmt::format_to(fmt::appender(out), "0x{:04X}", s.controlword);
  out.push_back(',');
  if (s.has_statusword) fmt::format_to(fmt::appender(out), "0x{:04X}", s.statusword);
  out.push_back(',');
  put(out, cia402::state_name(s.state));
  out.push_back(',');
  if (s.has_target) fmt::format_to(fmt::appender(out), "{}", s.target);
  out.push_back(',');
  if (s.has_actual) fmt::format_to(fmt::appender(out), "{}", s.actual);
  out.push_back(',');
  if (s.has_following_error) fmt::format_to(fmt::appender(out), "{}", s.following_error);
  if (counts_per_unit > 0) {
    out.push_back(',');
    if (s.has_target) fmt::format_to(fmt::appender(out), "{:.9g}", static_cast<double>(s.target) / counts_per_unit);
    out.push_back(',');
    if (s.has_actual) fmt::format_to(fmt::appender(out), "{:.9g}", static_cast<double>(s.actual) / counts_per_unit);
    out.push_back(',');
    if (s.has_following_error) fmt::format_to(fmt::appender(out), "{:.9g}", static_cast<double>(s.following_error) / counts_per_unit);
  }
  out.push_back('\n');
}

}  // namespace canmotion::trace
