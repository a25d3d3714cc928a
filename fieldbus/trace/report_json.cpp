// The `--json --summary` object of one bus: one method per member, in the
// order of the output (frames and kinds, sync with its jitter histogram,
// frames_per_cycle, bus_load, error_frames, then nodes[] with nmt, states,
// emcy, sdo_aborts, missing TPDOs and following_error).
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

class JsonSummary : detail::Summary {
 public:
  JsonSummary(const Analyzer& a, const ReportOptions& opt, Out& out) : Summary(a, opt, out) {}

  void render(std::string_view iface) {
    put(out_, "{\"iface\":");
    append_json_string(out_, iface);
    print(",\"frames\":{},\"t_first\":", b_.frames);
    time(b_.t_first);
    put(out_, ",\"t_last\":");
    time(b_.t_last);
    kinds();
    sync();
    frames_per_cycle();
    bus_load();
    error_frames();
    put(out_, ",\"nodes\":[");
    bool first = true;
    for (std::uint8_t n = 1; n <= kMaxNode; ++n) {
      if (!a_.node(n).seen) continue;
      if (!first) out_.push_back(',');
      first = false;
      node(n);
    }
    put(out_, "]}");
  }

 private:
  /// A time in seconds, or null without timestamps.
  void time(std::int64_t ns) {
    if (opt_.has_time) {
      append_time(out_, ns, opt_.time_digits);
    } else {
      put(out_, "null");
    }
  }

  /// `,"NAME":[` then `{"t":T...}` for each of `items` (`member` appends the
  /// rest of an object), then `]`.
  template <typename Item, typename Member>
  void timed_list(std::string_view open, const std::vector<Item>& items, Member member) {
    put(out_, open);
    for (std::size_t i = 0; i < items.size(); ++i) {
      put(out_, i ? ",{\"t\":" : "{\"t\":");
      time(items[i].t_ns);
      member(items[i]);
    }
  }

  void kinds() {
    put(out_, ",\"kinds\":{");
    bool first = true;
    for (std::size_t k = 0; k < b_.kind_counts.size(); ++k) {
      if (b_.kind_counts[k] == 0) continue;
      if (!first) out_.push_back(',');
      first = false;
      append_json_string(out_, detail::kind_label(k));
      print(":{}", b_.kind_counts[k]);
    }
    print("}},\"problems\":{}", b_.problems);
  }

  void sync() {
    print(",\"sync\":{{\"count\":{}", b_.syncs);
    if (opt_.has_time && b_.period_ns.n != 0) {
      print(",\"periods\":{},\"period_mean_us\":{:.3f},\"period_min_us\":{:.3f},\"period_max_us\":{:.3f},"
            "\"period_stddev_us\":{:.3f},\"nominal_us\":{:.3f},\"nominal_source\":",
            b_.period_ns.n, us(b_.period_ns.mean), us(b_.period_ns.min), us(b_.period_ns.max), us(b_.period_ns.stddev()),
            us(static_cast<double>(b_.nominal_period_ns)));
      append_json_string(out_, b_.nominal_source);
      const JitterHistogram& h = b_.jitter;
      print(",\"jitter_histogram\":{{\"bin_us\":{:.3f},\"first_bin_centre_us\":{:.3f},\"below\":{},\"above\":{},\"bins\":[",
            us(static_cast<double>(h.bin_width_ns)), us(static_cast<double>(-JitterHistogram::kHalfBins * h.bin_width_ns)),
            h.below, h.above);
      for (std::size_t i = 0; i < h.bins.size(); ++i) print("{}{}", i ? "," : "", h.bins[i]);
      put(out_, "]}");
    }
    put(out_, "}");
  }

  void frames_per_cycle() {
    const RunningStats& st = b_.frames_per_cycle_stats;
    if (st.n == 0) return;
    print(",\"frames_per_cycle\":{{\"mean\":{:.3f},\"min\":{:.0f},\"max\":{:.0f},\"histogram\":{{", st.mean, st.min,
          st.max);
    bool first = true;
    for (std::size_t i = 0; i < b_.frames_per_cycle.size(); ++i) {
      if (b_.frames_per_cycle[i] == 0) continue;
      print("{}\"{}\":{}", first ? "" : ",", i, b_.frames_per_cycle[i]);
      first = false;
    }
    put(out_, "}}");
  }

  void bus_load() {
    if (!opt_.has_time) return;
    print(",\"bus_load\":{{\"bitrate\":{:.0f},\"window_ms\":{:.3f},\"mean\":{:.4f},\"peak\":{:.4f},\"windows\":[",
          ao_.bitrate, static_cast<double>(b_.load_window_ns) / 1e6, b_.load_mean, b_.load_peak);
    for (std::size_t i = 0; i < b_.load.size(); ++i) print("{}{:.4f}", i ? "," : "", b_.load[i]);
    put(out_, "]}");
  }

  void error_frames() {
    print(",\"error_frames\":{{\"count\":{},\"list\":[", b_.error_frames);
    for (std::size_t i = 0; i < b_.error_list.size(); ++i) {
      if (i) out_.push_back(',');
      put(out_, "{\"t\":");
      time(b_.error_list[i].t_ns);
      put(out_, ",\"classes\":\"");
      append_error_details(out_, b_.error_list[i].classes, b_.error_list[i].data, 8);
      put(out_, "\"}");
    }
    put(out_, "]}");
  }

  void node(std::uint8_t n) {
    const NodeSummary& ns = a_.node(n);
    const NodeSettings& s = ao_.nodes[n];
    print("{{\"node\":{},\"name\":", n);
    append_json_string(out_, s.name);
    print(",\"frames\":{},\"tpdo\":{},\"rpdo\":{},\"sdo_requests\":{},\"sdo_responses\":{},\"heartbeats\":{}", ns.frames,
          ns.tpdos, ns.rpdos, ns.sdo_requests, ns.sdo_responses, ns.heartbeats);
    events(ns);
    missing_tpdos(ns);
    following_error(ns, s);
    put(out_, "}}");
  }

  /// nmt, states, emcy and sdo_aborts: the node's timed lists.
  void events(const NodeSummary& ns) {
    timed_list(",\"nmt\":[", ns.nmt,
               [&](const NmtChange& c) { print(",\"state\":\"{}\"}}", co::nmt_state_name(c.state)); });
    timed_list("],\"states\":[", ns.timeline, [&](const StateChange& c) {
      print(",\"state\":\"{}\",\"statusword\":{}", cia402::state_name(c.state), c.statusword);
      if (c.has_controlword) print(",\"controlword\":{}", c.controlword);
      put(out_, "}");
    });
    print("],\"states_dropped\":{},\"emcy_count\":{}", ns.timeline_dropped, ns.emcy_count);
    timed_list(",\"emcy\":[", ns.emcys, [&](const EmcyRecord& e) {
      append_emcy_json(out_, e.code, e.error_register);
      put(out_, "}");
    });
    print("],\"sdo_abort_count\":{}", ns.abort_count);
    timed_list(",\"sdo_aborts\":[", ns.aborts, [&](const AbortRecord& r) {
      print(",\"index\":{},\"sub\":{},\"code\":{},\"text\":", r.index, r.sub, r.code);
      append_json_string(out_, co::sdo_abort_text(r.code));
      put(out_, "}");
    });
  }

  void missing_tpdos(const NodeSummary& ns) {
    print("],\"syncs_checked\":{},\"missing_tpdo\":{},\"late_tpdo\":{},\"missing_tpdo_times\":[", ns.syncs_checked,
          ns.missing_tpdo, ns.late_tpdo);
    for (std::size_t i = 0; i < ns.missing_times.size(); ++i) {
      if (i) out_.push_back(',');
      time(ns.missing_times[i]);
    }
  }

  void following_error(const NodeSummary& ns, const NodeSettings& s) {
    print("],\"following_error\":{{\"samples\":{},\"max_abs_counts\":{},\"rms_counts\":{:.3f}", ns.ferr_count,
          ns.ferr_max_abs, ns.ferr_rms());
    if (ns.ferr_count != 0) {
      put(out_, ",\"t_max\":");
      time(ns.ferr_t_max);
    }
    print(",\"lag_cycles\":{},\"lag_fit\":[", ao_.ferr_lag_cycles);
    for (std::size_t l = 0; l < NodeSummary::kLagFit; ++l) {
      print("{}{{\"lag\":{},\"samples\":{},\"max_abs_counts\":{},\"rms_counts\":{:.3f}}}", l ? "," : "", l, ns.lag_count[l],
            ns.lag_max_abs[l], ns.lag_rms(l));
    }
    put(out_, "]");
    if (s.counts_per_unit > 0) {
      put(out_, ",\"unit\":");
      append_json_string(out_, s.unit);
      print(",\"max_abs_units\":{:.9g},\"rms_units\":{:.9g}", static_cast<double>(ns.ferr_max_abs) / s.counts_per_unit,
            ns.ferr_rms() / s.counts_per_unit);
    }
  }

};

}  // namespace

void format_summary_json(std::string_view iface, const Analyzer& a, const ReportOptions& opt, Out& out) {
  JsonSummary(a, opt, out).render(iface);
}

}  // namespace canmotion::trace
