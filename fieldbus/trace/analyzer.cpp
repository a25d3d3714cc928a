#include "fieldbus/trace/analyzer.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace canmotion::trace {

namespace co = canmotion::canopen;

/// Calibration size of the jitter histogram: the nominal period (if not
/// given) and the bin width come from the first kCalibration periods.
static constexpr std::size_t kCalibration = 256;

void RunningStats::add(double x) noexcept {
  ++n;
  if (n == 1) {
    min = max = x;
  } else {
    min = std::min(min, x);
    max = std::max(max, x);
  }
  const double delta = x - mean;
  mean += delta / static_cast<double>(n);
  m2 += delta * (x - mean);
}

double RunningStats::stddev() const noexcept { return n > 1 ? std::sqrt(m2 / static_cast<double>(n - 1)) : 0.0; }

double NodeSummary::ferr_rms() const noexcept {
  return ferr_count != 0 ? std::sqrt(ferr_sum_sq / static_cast<double>(ferr_count)) : 0.0;
}

double NodeSummary::lag_rms(std::size_t lag) const noexcept {
  return lag < kLagFit && lag_count[lag] != 0 ? std::sqrt(lag_sum_sq[lag] / static_cast<double>(lag_count[lag])) : 0.0;
}

std::size_t NodeSummary::best_lag() const noexcept {
  std::size_t best = kLagFit;
  for (std::size_t l = 0; l < kLagFit; ++l) {
    if (lag_count[l] == 0) continue;
    if (best == kLagFit || lag_rms(l) < lag_rms(best)) best = l;
  }
  return best;
}

std::uint32_t frame_bits_worst_case(const can::Frame& f) noexcept {
  if (f.error()) return 0;  // reported by the controller, not a frame on the wire
  const std::uint32_t s = f.remote() ? 0U : std::min<std::uint32_t>(f.len, 8U);
  if (f.extended()) return 8 * s + 67 + (53 + 8 * s) / 4;
  return 8 * s + 47 + (33 + 8 * s) / 4;
}

Analyzer::Analyzer(AnalyzerOptions opt) : opt_(std::move(opt)) {
  if (opt_.load_window_ns <= 0) opt_.load_window_ns = 100'000'000;
  if (opt_.max_load_windows < 2) opt_.max_load_windows = 2;
  load_window_ = opt_.load_window_ns;
  calib_.reserve(kCalibration);
}

namespace {
// 1-2-5 series, at least 1 us.
std::int64_t nice_width(double x) {
  std::int64_t w = 1000;
  while (true) {
    for (std::int64_t m : {1, 2, 5}) {
      if (static_cast<double>(w * m) >= x) return w * m;
    }
    w *= 10;
    if (w > 10'000'000'000LL) return w;
  }
}
}  // namespace

void Analyzer::calibrate(const Decoder& decoder) {
  if (calibrated_) return;
  calibrated_ = true;
  if (opt_.nominal_period_ns > 0) {
    bus_.nominal_period_ns = opt_.nominal_period_ns;
    bus_.nominal_source = opt_.nominal_source;
  } else if (decoder.sync_period_from_trace_ns() > 0) {
    bus_.nominal_period_ns = decoder.sync_period_from_trace_ns();
    bus_.nominal_source = "trace (0x1006)";
  } else if (!calib_.empty()) {
    // The mean of the first periods, rounded to two significant digits
    // (1972.8 us -> 2000 us, 1000.3 us -> 1000 us, 251 us -> 250 us).
    double sum = 0;
    for (std::int64_t p : calib_) sum += static_cast<double>(p);
    const double mean = sum / static_cast<double>(calib_.size());
    double step = 1;
    while (step * 100 <= mean) step *= 10;
    bus_.nominal_period_ns = static_cast<std::int64_t>(std::llround(mean / step) * static_cast<long long>(step));
    if (bus_.nominal_period_ns <= 0) bus_.nominal_period_ns = static_cast<std::int64_t>(mean);
    bus_.nominal_source = "mean of the first periods, rounded";
  }
  // Bin width: the 95th percentile of |deviation| spread over the half-width.
  std::vector<std::int64_t> dev;
  dev.reserve(calib_.size());
  for (std::int64_t p : calib_) dev.push_back(std::llabs(p - bus_.nominal_period_ns));
  double spread = 0;
  if (!dev.empty()) {
    const std::size_t k = std::min(dev.size() - 1, dev.size() * 95 / 100);
    std::nth_element(dev.begin(), dev.begin() + static_cast<std::ptrdiff_t>(k), dev.end());
    spread = static_cast<double>(dev[k]);
  }
  bus_.jitter.bin_width_ns = nice_width(spread / (JitterHistogram::kHalfBins - 2));
  for (std::int64_t p : calib_) add_jitter(p);
  calib_.clear();
  calib_.shrink_to_fit();
}

void Analyzer::add_jitter(std::int64_t p) {
  const double dev = static_cast<double>(p - bus_.nominal_period_ns);
  const double w = static_cast<double>(bus_.jitter.bin_width_ns);
  const auto bin = static_cast<std::int64_t>(std::floor(dev / w + 0.5)) + JitterHistogram::kHalfBins;
  if (bin < 0) {
    ++bus_.jitter.below;
  } else if (bin >= static_cast<std::int64_t>(JitterHistogram::kBins)) {
    ++bus_.jitter.above;
  } else {
    ++bus_.jitter.bins[static_cast<std::size_t>(bin)];
  }
}

void Analyzer::add_period(std::int64_t p) {
  bus_.period_ns.add(static_cast<double>(p));
  if (!calibrated_) {
    calib_.push_back(p);
    return;
  }
  add_jitter(p);
}

void Analyzer::add_load(std::int64_t t, std::uint32_t bits) {
  std::int64_t rel = t - bus_.t_first;
  if (rel < 0) rel = 0;  // out-of-order timestamps count into the first window
  auto idx = static_cast<std::size_t>(rel / load_window_);
  while (idx >= opt_.max_load_windows) {
    // Full: merge pairs of windows and double the width (bounded memory).
    std::vector<std::uint64_t> merged((load_bits_.size() + 1) / 2, 0);
    for (std::size_t i = 0; i < load_bits_.size(); ++i) merged[i / 2] += load_bits_[i];
    load_bits_ = std::move(merged);
    load_window_ *= 2;
    idx = static_cast<std::size_t>(rel / load_window_);
  }
  if (idx >= load_bits_.size()) load_bits_.resize(idx + 1, 0);
  load_bits_[idx] += bits;
}

void Analyzer::set_nmt(std::uint8_t node, co::NmtState s, std::int64_t t) {
  Live& l = live_[node];
  if (l.nmt == s) return;
  l.nmt = s;
  if (s != co::NmtState::kOperational) l.producing = false;
  NodeSummary& ns = nodes_[node];
  ns.seen = true;
  if (ns.nmt.size() < opt_.timeline_cap) {
    ns.nmt.push_back(NmtChange{t, s});
  } else {
    ++ns.nmt_dropped;
  }
}

void Analyzer::on_sync(const Decoded& d, const Decoder& decoder) {
  const std::int64_t t = d.tf.t_ns;
  ++bus_.syncs;
  if (have_sync_) {
    add_period(t - last_sync_);
    if (!calibrated_ && calib_.size() >= kCalibration) calibrate(decoder);
    const std::size_t fpc = std::min<std::size_t>(frames_since_sync_, bus_.frames_per_cycle.size() - 1);
    ++bus_.frames_per_cycle[fpc];
    bus_.frames_per_cycle_stats.add(static_cast<double>(frames_since_sync_));
  }
  // Missing feedback: a node that produces synchronous TPDOs should have sent
  // one since the previous SYNC (every n-th SYNC for transmission type n).
  for (std::uint8_t n = 1; n <= kMaxNode; ++n) {
    Live& l = live_[n];
    if (!l.producing) continue;
    // Misses of earlier cycles not made up by late TPDOs in this cycle are final.
    if (l.tpdos_this_cycle != 0) l.unconfirmed_missing = 0;
    l.tpdos_this_cycle = 0;
    ++l.syncs_since_tpdo;
    std::uint8_t every = 1;
    const std::uint8_t tt = decoder.tpdo_transmission_type(n, 1);
    if (tt >= 1 && tt <= 240) every = tt;
    if (tt == 0 || (tt > 240 && tt != 255)) continue;  // acyclic / event driven: nothing expected
    if (l.syncs_since_tpdo <= every) {
      if (l.syncs_since_tpdo == every) ++nodes_[n].syncs_checked;
      continue;
    }
    // The previous cycle ended without a TPDO.
    NodeSummary& ns = nodes_[n];
    ++ns.syncs_checked;
    ++ns.missing_tpdo;
    if (ns.missing_times.size() < opt_.list_cap) ns.missing_times.push_back(last_sync_);
    l.syncs_since_tpdo = every;  // count each silent cycle once
    if (every == 1 && l.unconfirmed_missing < 8) ++l.unconfirmed_missing;
  }
  const std::uint32_t lag = std::min(opt_.ferr_lag_cycles, AnalyzerOptions::kMaxLag);
  for (Live& l : live_) {
    if (!l.has_target) continue;
    // Ring of the targets applied at the last lag + 1 SYNCs.
    l.history_head = (l.history_head + 1) % static_cast<std::uint32_t>(l.history.size());
    l.history[l.history_head] = l.target;
    if (l.history_len < l.history.size()) ++l.history_len;
    if (l.history_len > lag) {
      l.has_applied = true;
      const auto n = static_cast<std::uint32_t>(l.history.size());
      l.applied = l.history[(l.history_head + n - lag) % n];
    }
  }
  have_sync_ = true;
  last_sync_ = t;
  frames_since_sync_ = 0;
}

void Analyzer::account(const Decoded& d) {
  const std::int64_t t = d.tf.t_ns;
  if (bus_.frames == 0) {
    bus_.t_first = t;
    load_window_ = opt_.load_window_ns;
  }
  ++bus_.frames;
  bus_.t_last = t;
  ++bus_.kind_counts[static_cast<std::size_t>(d.kind)];
  if (d.problem != nullptr) ++bus_.problems;
  add_load(t, frame_bits_worst_case(d.tf.frame));
}

void Analyzer::on_error_frame(const Decoded& d) {
  ++bus_.error_frames;
  for (unsigned b = 0; b < bus_.error_class_counts.size(); ++b) {
    if ((d.tf.frame.id & (1U << b)) != 0) ++bus_.error_class_counts[b];
  }
  if (bus_.error_list.size() < opt_.list_cap) {
    bus_.error_list.push_back(ErrorFrameRecord{d.tf.t_ns, d.tf.frame.id, d.tf.frame.data});
  }
}

void Analyzer::on_nmt_command(const Decoded& d) {
  // Commands change the NMT state of the addressed nodes; keep the
  // "producing" flag honest so stopped nodes do not count as missing TPDOs.
  const auto apply = [&](std::uint8_t n) {
    if (d.nmt_command == 0x01) return;  // start: wait for its heartbeat/TPDOs
    live_[n].producing = false;
  };
  if (d.nmt_target == 0) {
    for (std::uint8_t n = 1; n <= kMaxNode; ++n) apply(n);
  } else if (d.nmt_target <= kMaxNode) {
    apply(d.nmt_target);
  }
}

void Analyzer::on_tpdo1(NodeSummary& ns, Live& l) {
  if (l.tpdos_this_cycle != 0 && l.unconfirmed_missing != 0) {
    // A second TPDO in one cycle: the one counted missing came late.
    --l.unconfirmed_missing;
    if (ns.missing_tpdo <= ns.missing_times.size() && !ns.missing_times.empty()) ns.missing_times.pop_back();
    --ns.missing_tpdo;
    ++ns.late_tpdo;
  }
  ++l.tpdos_this_cycle;
  l.producing = true;
  l.syncs_since_tpdo = 0;
}

void Analyzer::count_node_event(const Decoded& d, NodeSummary& ns, Live& l) {
  const std::int64_t t = d.tf.t_ns;
  switch (d.kind) {
    case EventKind::kEmcy:
      ++ns.emcy_count;
      if (ns.emcys.size() < opt_.list_cap) ns.emcys.push_back(EmcyRecord{t, d.emcy_code, d.emcy_register, d.emcy_vendor});
      break;
    case EventKind::kBootUp:
      set_nmt(d.node, co::NmtState::kBootUp, t);
      // A reboot forgets the CiA 402 state.
      l.state = cia402::State::kUnknown;
      l.has_sw = false;
      break;
    case EventKind::kHeartbeat:
      ++ns.heartbeats;
      if (d.nmt_state != co::NmtState::kUnknown) set_nmt(d.node, d.nmt_state, t);
      break;
    case EventKind::kSdo:
      ++(d.sdo_response ? ns.sdo_responses : ns.sdo_requests);
      if (d.sdo.kind == canopen::sdo::SdoFrameKind::kAbort) {
        ++ns.abort_count;
        if (ns.aborts.size() < opt_.list_cap) ns.aborts.push_back(AbortRecord{t, d.sdo_index, d.sdo_sub, d.sdo.abort_code, d.sdo_response});
      }
      break;
    case EventKind::kPdo:
      if (!d.pdo_tx) {
        ++ns.rpdos;
        break;
      }
      ++ns.tpdos;
      if (d.pdo_number == 1) on_tpdo1(ns, l);
      break;
    default:
      break;
  }
}

void Analyzer::track_drive(const Decoded& d, NodeSummary& ns, Live& l) {
  if (d.has_controlword) {
    l.has_cw = true;
    l.cw = d.controlword;
  }
  if (d.has_target) {
    l.has_target = true;
    l.target = d.target_position;
  }
  if (!d.has_statusword) return;
  const cia402::State s = cia402::decode_state(d.statusword);
  if (!l.has_sw || s != l.state) {
    if (ns.timeline.size() < opt_.timeline_cap) {
      ns.timeline.push_back(StateChange{d.tf.t_ns, s, d.statusword, l.has_cw, l.cw});
    } else {
      ++ns.timeline_dropped;
    }
  }
  l.has_sw = true;
  l.sw = d.statusword;
  l.state = s;
}

Sample Analyzer::sample_of(const Decoded& d, NodeSummary& ns, const Live& l) {
  Sample s;
  s.node = d.node;
  s.t_ns = d.tf.t_ns;
  s.has_controlword = l.has_cw;
  s.controlword = l.cw;
  s.has_statusword = l.has_sw;
  s.statusword = l.sw;
  s.state = l.state;
  s.has_target = l.has_applied;
  s.target = l.applied;
  s.has_actual = d.has_actual;
  s.actual = d.actual_position;
  const bool enabled = d.has_actual && l.has_sw && l.state == cia402::State::kOperationEnabled;
  if (enabled && l.has_applied) {
    s.has_following_error = true;
    s.following_error = l.applied - d.actual_position;
    const std::int64_t a = s.following_error < 0 ? -s.following_error : s.following_error;
    ++ns.ferr_count;
    ns.ferr_sum_sq += static_cast<double>(s.following_error) * static_cast<double>(s.following_error);
    if (a > ns.ferr_max_abs || ns.ferr_count == 1) {
      ns.ferr_max_abs = a;
      ns.ferr_at_max = s.following_error;
      ns.ferr_t_max = d.tf.t_ns;
    }
  }
  if (enabled) {
    // The same error against the targets applied 0..kLagFit-1 SYNCs earlier.
    const auto n = static_cast<std::uint32_t>(l.history.size());
    for (std::uint32_t lag = 0; lag < NodeSummary::kLagFit && lag < l.history_len; ++lag) {
      const std::int64_t e = l.history[(l.history_head + n - lag) % n] - d.actual_position;
      ++ns.lag_count[lag];
      ns.lag_sum_sq[lag] += static_cast<double>(e) * static_cast<double>(e);
      ns.lag_max_abs[lag] = std::max(ns.lag_max_abs[lag], e < 0 ? -e : e);
    }
  }
  return s;
}

bool Analyzer::feed(const Decoded& d, const Decoder& decoder, Sample* sample) {
  account(d);
  if (d.kind == EventKind::kSync) {
    on_sync(d, decoder);
    return false;
  }
  ++frames_since_sync_;
  if (d.kind == EventKind::kErrorFrame) {
    on_error_frame(d);
    return false;
  }
  if (d.kind == EventKind::kNmt && d.problem == nullptr) {
    on_nmt_command(d);
    return false;
  }
  if (d.node == 0 || d.node > kMaxNode) return false;
  NodeSummary& ns = nodes_[d.node];
  Live& l = live_[d.node];
  ns.seen = true;
  ++ns.frames;
  count_node_event(d, ns, l);
  track_drive(d, ns, l);
  // A sample per TPDO that carries the statusword or the actual position.
  if (d.kind != EventKind::kPdo || !d.pdo_tx || (!d.has_statusword && !d.has_actual)) return false;
  const Sample s = sample_of(d, ns, l);
  if (sample != nullptr) *sample = s;
  return true;
}

void Analyzer::finish(const Decoder& decoder) {
  calibrate(decoder);
  bus_.load_window_ns = load_window_;
  bus_.load.clear();
  bus_.load_peak = 0;
  double total_bits = 0;
  const double cap_bits_per_window = opt_.bitrate * static_cast<double>(load_window_) / 1e9;
  for (std::size_t i = 0; i < load_bits_.size(); ++i) {
    double window_bits = cap_bits_per_window;
    if (i + 1 == load_bits_.size()) {
      // The last window is partial: divide by the time it covers.
      const auto covered = static_cast<double>(bus_.t_last - bus_.t_first) - static_cast<double>(i) * static_cast<double>(load_window_);
      if (covered > 0 && covered < static_cast<double>(load_window_)) window_bits = opt_.bitrate * covered / 1e9;
    }
    const double l = window_bits > 0 ? static_cast<double>(load_bits_[i]) / window_bits : 0.0;
    bus_.load.push_back(l);
    bus_.load_peak = std::max(bus_.load_peak, l);
    total_bits += static_cast<double>(load_bits_[i]);
  }
  const double dur = static_cast<double>(bus_.t_last - bus_.t_first) / 1e9;
  bus_.load_mean = dur > 0 ? total_bits / (opt_.bitrate * dur) : 0.0;
}

}  // namespace canmotion::trace
