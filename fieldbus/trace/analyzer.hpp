#pragma once
/// \file
/// Streaming analysis of a decoded trace (`cantrace --summary`): per-node
/// CiA 402 state timeline, EMCY list, SYNCs without TPDO, following error;
/// bus SYNC period statistics and jitter histogram, bus load over time,
/// frames per cycle, error frames.
///
/// Memory is bounded: every list has a fixed cap (the dropped entries are
/// counted), the bus-load series keeps at most `max_load_windows` windows by
/// doubling the window width when it fills up, and the jitter histogram has a
/// fixed number of bins. So memory does not grow with the trace length.
/// Not realtime-safe (lists allocate up to their caps); meant for tools.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "fieldbus/canopen/nmt.hpp"
#include "fieldbus/cia402/cia402.hpp"
#include "fieldbus/trace/decoder.hpp"

namespace canmotion::trace {

/// Per-node settings from a configuration (optional).
struct NodeSettings {
  std::string name;             ///< axis name, "" if none
  double counts_per_unit = 0;   ///< 0 = no user units
  std::string unit;             ///< "mm", "deg", ...
};

/// Analysis settings.
struct AnalyzerOptions {
  std::int64_t nominal_period_ns = 0;  ///< 0: from a 0x1006 write in the trace, else the rounded mean of the first periods
  std::string nominal_source = "option";  ///< shown in the summary when nominal_period_ns is given ("option", "config")
  double bitrate = 1'000'000.0;        ///< bit/s, for the bus load
  std::int64_t load_window_ns = 100'000'000;  ///< initial bus-load window (doubles when the series is full)
  std::size_t max_load_windows = 512;         ///< cap of the bus-load series
  std::size_t timeline_cap = 1000;            ///< state changes kept per node
  std::size_t list_cap = 256;                 ///< EMCYs, aborts, missing-TPDO times, error frames kept
  /// Following error compares the actual position in the TPDO after SYNC k
  /// with the target applied at SYNC k - lag (0: a drive that reports the
  /// position reached for the target applied at this SYNC, like canmotion's
  /// emulator; 1: a drive that samples its position at SYNC before applying).
  std::uint32_t ferr_lag_cycles = 0;
  static constexpr std::uint32_t kMaxLag = 15;
  std::array<NodeSettings, kMaxNode + 1> nodes{};
};

/// One row of per-node cyclic data (one per TPDO carrying statusword or actual position).
struct Sample {
  std::uint8_t node = 0;
  std::int64_t t_ns = 0;
  bool has_controlword = false;
  std::uint16_t controlword = 0;
  bool has_statusword = false;
  std::uint16_t statusword = 0;
  cia402::State state = cia402::State::kUnknown;
  bool has_target = false;
  std::int64_t target = 0;  ///< target applied at the last SYNC (counts)
  bool has_actual = false;
  std::int64_t actual = 0;  ///< position actual value (counts)
  bool has_following_error = false;
  std::int64_t following_error = 0;  ///< target - actual (counts), only in Operation enabled
};

struct StateChange {
  std::int64_t t_ns = 0;
  cia402::State state = cia402::State::kUnknown;
  std::uint16_t statusword = 0;
  bool has_controlword = false;
  std::uint16_t controlword = 0;  ///< last controlword sent before the change
};

struct NmtChange {
  std::int64_t t_ns = 0;
  canopen::NmtState state = canopen::NmtState::kUnknown;
};

struct EmcyRecord {
  std::int64_t t_ns = 0;
  std::uint16_t code = 0;
  std::uint8_t error_register = 0;
  std::array<std::uint8_t, 5> vendor{};
};

struct AbortRecord {
  std::int64_t t_ns = 0;
  std::uint16_t index = 0;
  std::uint8_t sub = 0;
  std::uint32_t code = 0;
  bool by_server = true;
};

/// Running statistics (Welford), min and max.
struct RunningStats {
  std::uint64_t n = 0;
  double mean = 0;
  double m2 = 0;
  double min = 0;
  double max = 0;
  void add(double x) noexcept;
  [[nodiscard]] double stddev() const noexcept;
};

struct NodeSummary {
  bool seen = false;
  std::uint64_t frames = 0, tpdos = 0, rpdos = 0, sdo_requests = 0, sdo_responses = 0, heartbeats = 0;
  std::vector<StateChange> timeline;
  std::uint64_t timeline_dropped = 0;
  std::vector<NmtChange> nmt;
  std::uint64_t nmt_dropped = 0;
  std::vector<EmcyRecord> emcys;
  std::uint64_t emcy_count = 0;
  std::vector<AbortRecord> aborts;
  std::uint64_t abort_count = 0;
  std::uint64_t syncs_checked = 0;   ///< SYNC cycles in which a TPDO was expected
  std::uint64_t missing_tpdo = 0;    ///< of those, cycles without a TPDO (late ones excluded)
  std::uint64_t late_tpdo = 0;       ///< TPDOs that came one cycle late (two in the next cycle)
  std::vector<std::int64_t> missing_times;  ///< SYNC times that got no TPDO (capped)
  std::uint64_t ferr_count = 0;
  double ferr_sum_sq = 0;
  std::int64_t ferr_max_abs = 0;
  std::int64_t ferr_at_max = 0;       ///< signed value at the maximum
  std::int64_t ferr_t_max = 0;
  [[nodiscard]] double ferr_rms() const noexcept;
  /// The same statistics for lags 0..kLagFit-1 SYNC cycles, to tell which
  /// lag the drive actually has (see AnalyzerOptions::ferr_lag_cycles).
  static constexpr std::size_t kLagFit = 4;
  std::array<std::uint64_t, kLagFit> lag_count{};
  std::array<double, kLagFit> lag_sum_sq{};
  std::array<std::int64_t, kLagFit> lag_max_abs{};
  [[nodiscard]] double lag_rms(std::size_t lag) const noexcept;
  /// Lag with the smallest RMS following error (kLagFit if no samples).
  [[nodiscard]] std::size_t best_lag() const noexcept;
};

struct ErrorFrameRecord {
  std::int64_t t_ns = 0;
  std::uint32_t classes = 0;
  std::array<std::uint8_t, 8> data{};
};

/// Jitter histogram: bins of `bin_width_ns` centred on 0 deviation from the nominal period.
struct JitterHistogram {
  static constexpr int kHalfBins = 20;
  static constexpr std::size_t kBins = 2 * kHalfBins + 1;
  std::int64_t bin_width_ns = 0;
  std::array<std::uint64_t, kBins> bins{};
  std::uint64_t below = 0;  ///< deviation below the first bin
  std::uint64_t above = 0;  ///< deviation above the last bin
  /// Lower edge of bin i in ns (deviation).
  [[nodiscard]] double lower_edge_ns(std::size_t i) const noexcept {
    return (static_cast<double>(i) - kHalfBins - 0.5) * static_cast<double>(bin_width_ns);
  }
};

struct BusSummary {
  std::uint64_t frames = 0;
  std::int64_t t_first = 0, t_last = 0;
  std::array<std::uint64_t, 12> kind_counts{};  ///< indexed by EventKind
  std::uint64_t syncs = 0;
  RunningStats period_ns;             ///< SYNC-to-SYNC period
  std::int64_t nominal_period_ns = 0;
  std::string nominal_source;         ///< "option", "trace (0x1006)", "median of first periods", ""
  JitterHistogram jitter;
  std::array<std::uint64_t, 65> frames_per_cycle{};  ///< index = frames between two SYNCs (64 = 64 or more)
  RunningStats frames_per_cycle_stats;
  std::int64_t load_window_ns = 0;
  std::vector<double> load;           ///< bus load (0..1) per window from t_first
  double load_mean = 0, load_peak = 0;
  std::uint64_t error_frames = 0;
  std::array<std::uint64_t, 16> error_class_counts{};
  std::vector<ErrorFrameRecord> error_list;
  std::uint64_t problems = 0;  ///< frames with a protocol problem
};

/// Streaming analyzer; feed every decoded frame in order.
class Analyzer {
 public:
  explicit Analyzer(AnalyzerOptions opt);

  /// Account one decoded frame. `decoder` supplies TPDO transmission types
  /// and the 0x1006 period seen in the trace. Returns true and fills `sample`
  /// when the frame is a TPDO carrying statusword or actual position.
  bool feed(const Decoded& d, const Decoder& decoder, Sample* sample);

  /// Finish (computes the jitter histogram if fewer periods than the
  /// calibration size were seen, and bus-load averages). Call once at the end.
  void finish(const Decoder& decoder);

  [[nodiscard]] const BusSummary& bus() const noexcept { return bus_; }
  [[nodiscard]] const NodeSummary& node(std::uint8_t n) const noexcept { return nodes_[n]; }
  [[nodiscard]] const AnalyzerOptions& options() const noexcept { return opt_; }

 private:
  struct Live {
    bool has_cw = false;
    std::uint16_t cw = 0;
    bool has_sw = false;
    std::uint16_t sw = 0;
    cia402::State state = cia402::State::kUnknown;
    bool has_target = false;
    std::int64_t target = 0;
    bool has_applied = false;
    std::int64_t applied = 0;
    std::array<std::int64_t, AnalyzerOptions::kMaxLag + 1> history{};  // targets applied at the last SYNCs
    std::uint32_t history_len = 0;
    std::uint32_t history_head = 0;
    bool producing = false;      // TPDOs expected on SYNC
    std::uint32_t syncs_since_tpdo = 0;
    std::uint32_t tpdos_this_cycle = 0;     // TPDO1s since the last SYNC
    std::uint32_t unconfirmed_missing = 0;  // misses a late TPDO may still make up
    canopen::NmtState nmt = canopen::NmtState::kUnknown;
  };
  // feed(), by concern: the bus counters, the frames without a node, the
  // node's counters and lists, its drive state, the sample of a TPDO.
  void account(const Decoded& d);
  void on_error_frame(const Decoded& d);
  void on_nmt_command(const Decoded& d);
  void count_node_event(const Decoded& d, NodeSummary& ns, Live& l);
  static void on_tpdo1(NodeSummary& ns, Live& l);
  void track_drive(const Decoded& d, NodeSummary& ns, Live& l);
  static Sample sample_of(const Decoded& d, NodeSummary& ns, const Live& l);
  void on_sync(const Decoded& d, const Decoder& decoder);
  void add_period(std::int64_t p);
  void calibrate(const Decoder& decoder);
  void add_jitter(std::int64_t p);
  void add_load(std::int64_t t, std::uint32_t bits);
  void set_nmt(std::uint8_t node, canopen::NmtState s, std::int64_t t);

  AnalyzerOptions opt_;
  BusSummary bus_;
  std::array<NodeSummary, kMaxNode + 1> nodes_{};
  std::array<Live, kMaxNode + 1> live_{};
  bool have_sync_ = false;
  std::int64_t last_sync_ = 0;
  std::uint32_t frames_since_sync_ = 0;
  std::vector<std::int64_t> calib_;  // first periods, until the histogram is calibrated
  bool calibrated_ = false;
  std::vector<std::uint64_t> load_bits_;
  std::int64_t load_window_ = 0;
};

/// Worst-case length in bits of a classical CAN frame including stuff bits
/// and the 3-bit intermission (shared/reference/cia402.md §6).
std::uint32_t frame_bits_worst_case(const can::Frame& f) noexcept;

}  // namespace canmotion::trace
