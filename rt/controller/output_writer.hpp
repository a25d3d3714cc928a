#pragma once
/// \file
/// Writes canmotiond's --trace (candump -L lines) and --csv (telemetry rows)
/// files from the records the controller's rings deliver. The RT thread never
/// formats: it pushes TraceRecord/Sample into the rings; the thread that
/// drains them (housekeeping, or the --sim loop between cycles) hands each
/// record to this writer, which either formats it at once ("inline": real
/// time, where a thousand cycles a second make little text) or copies it into
/// a batch that a writer thread formats and writes ("threaded": --sim, where
/// the text of hundreds of simulated seconds a second costs as much CPU as
/// the simulation; the two then run on two CPUs). Both modes give the same
/// bytes, in the order of the records; a full batch queue makes the caller
/// wait, so nothing is ever dropped. No stdio, no iostreams: format_candump_line,
/// format_telemetry_csv_row and OutputFile (large write(2) blocks).
///
/// Not realtime-safe: call from one non-RT thread.

#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "fieldbus/can/frame.hpp"
#include "rt/controller/controller.hpp"
#include "rt/text_output.hpp"

namespace canmotion::rt {

/// What OutputWriter writes.
struct OutputWriterConfig {
  std::string trace_path;                ///< "" = no trace
  std::string csv_path;                  ///< "" = no CSV
  std::vector<std::string> trace_names;  ///< interface name per bus index, for the trace lines
  std::vector<std::string> axis_names;   ///< per axis index, for the CSV rows
  double period_s = 0.001;               ///< CSV time column = cycle x period_s
  bool threaded = false;                 ///< format and write on a writer thread (--sim)
  std::size_t buffer_bytes = OutputFile::kDefaultBuffer;  ///< per file
};

class OutputWriter {
 public:
  /// Records per batch handed to the writer thread, and batches in flight:
  /// the caller waits when all are queued. 4096 trace records are about 200
  /// cycles of 8 axes on 4 buses; the 4 batches hold 1.4 MB.
  static constexpr std::size_t kBatchRecords = 4096;
  static constexpr std::size_t kBatches = 4;

  /// Opens (creates/truncates) the files and writes the CSV header; starts
  /// the writer thread when threaded. Throws std::runtime_error naming the
  /// file ("cannot write trace file 'x': Permission denied").
  explicit OutputWriter(OutputWriterConfig config);
  OutputWriter(const OutputWriter&) = delete;
  OutputWriter& operator=(const OutputWriter&) = delete;
  /// close().
  ~OutputWriter();

  bool tracing() const noexcept { return trace_.is_open(); }
  bool recording_csv() const noexcept { return csv_.is_open(); }

  /// One trace line: `frame` at `t_ns` (ns since the epoch: the caller puts
  /// the stamp on the realtime scale) on bus `bus`. Ignored without a trace file.
  void trace(const can::Frame& frame, std::int64_t t_ns, std::uint8_t bus);
  /// One CSV row. Ignored without a CSV file.
  void sample(const Sample& s);

  /// Writes everything handed over so far, waits for the writer thread, and
  /// closes the files. Returns what went wrong ("writing 'x' failed: No space
  /// left on device"), "" if nothing. Safe to call twice.
  std::string close();

 private:
  struct TraceItem {
    can::Frame frame;
    std::int64_t t_ns;
    std::uint8_t bus;
  };
  struct Batch {
    std::vector<TraceItem> traces;
    std::vector<Sample> samples;
  };

  void write_trace(const TraceItem& t);
  void write_sample(const Sample& s);
  void hand_over();          // the current batch to the writer thread
  void writer_loop();

  OutputWriterConfig config_;
  OutputFile trace_;
  OutputFile csv_;
  std::size_t row_max_ = 0;  // longest CSV row (longest axis name)
  bool closed_ = false;

  // Threaded mode.
  std::unique_ptr<Batch> current_;
  std::mutex mu_;
  std::condition_variable cv_;
  std::deque<std::unique_ptr<Batch>> full_;  // to the writer thread
  std::deque<std::unique_ptr<Batch>> free_;  // back to the caller
  bool done_ = false;
  std::thread thread_;
};

}  // namespace canmotion::rt
