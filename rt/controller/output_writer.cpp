#include "rt/controller/output_writer.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <stdexcept>
#include <system_error>

#include "fieldbus/can/candump_format.hpp"
#include "rt/controller/telemetry_csv.hpp"

namespace canmotion::rt {

OutputWriter::OutputWriter(OutputWriterConfig config) : config_(std::move(config)) {
  if (!config_.trace_path.empty()) {
    try {
      trace_.open(config_.trace_path, config_.buffer_bytes);
    } catch (const std::system_error& e) {
      throw std::runtime_error(
          fmt::format("cannot write trace file '{}': {}", config_.trace_path, e.code().message()));
    }
  }
  if (!config_.csv_path.empty()) {
    try {
      csv_.open(config_.csv_path, config_.buffer_bytes);
    } catch (const std::system_error& e) {
      throw std::runtime_error(fmt::format("cannot write CSV file '{}': {}", config_.csv_path, e.code().message()));
    }
    csv_.write(kTelemetryCsvHeader);
  }
  for (const auto& n : config_.axis_names) row_max_ = std::max(row_max_, telemetry_csv_row_max(n.size()));
  if (config_.threaded && (trace_.is_open() || csv_.is_open())) {
    for (std::size_t i = 0; i < kBatches; ++i) {
      auto b = std::make_unique<Batch>();
      b->traces.reserve(kBatchRecords);
      b->samples.reserve(kBatchRecords);
      free_.push_back(std::move(b));
    }
    current_ = std::move(free_.front());
    free_.pop_front();
    thread_ = std::thread([this] { writer_loop(); });
  }
}

OutputWriter::~OutputWriter() { (void)close(); }

void OutputWriter::write_trace(const TraceItem& t) {
  static constexpr std::size_t kLine = can::kCandumpLineMax + 2;
  char* line = trace_.reserve(kLine);
  std::string_view iface = "?";
  if (t.bus < config_.trace_names.size()) iface = config_.trace_names[t.bus];
  const std::size_t n = can::format_candump_line({line, kLine - 1}, t.frame, t.t_ns, iface);
  if (n > 0) {
    line[n] = '\n';
    trace_.commit(line + n + 1);
  }
}

void OutputWriter::write_sample(const Sample& s) {
  std::string_view axis = "?";
  if (s.axis < config_.axis_names.size()) axis = config_.axis_names[s.axis];
  csv_.commit(format_telemetry_csv_row(csv_.reserve(std::max(row_max_, telemetry_csv_row_max(1))), s,
                                       config_.period_s, axis));
}

void OutputWriter::trace(const can::Frame& frame, std::int64_t t_ns, std::uint8_t bus) {
  if (!trace_.is_open() || closed_) return;
  if (!current_) {
    write_trace({frame, t_ns, bus});
    return;
  }
  current_->traces.push_back({frame, t_ns, bus});
  if (current_->traces.size() >= kBatchRecords) hand_over();
}

void OutputWriter::sample(const Sample& s) {
  if (!csv_.is_open() || closed_) return;
  if (!current_) {
    write_sample(s);
    return;
  }
  current_->samples.push_back(s);
  if (current_->samples.size() >= kBatchRecords) hand_over();
}

void OutputWriter::hand_over() {
  std::unique_lock lock(mu_);
  full_.push_back(std::move(current_));
  cv_.notify_all();
  cv_.wait(lock, [this] { return !free_.empty(); });  // all batches queued: wait (nothing is dropped)
  current_ = std::move(free_.front());
  free_.pop_front();
}

void OutputWriter::writer_loop() {
  for (;;) {
    std::unique_ptr<Batch> b;
    {
      std::unique_lock lock(mu_);
      cv_.wait(lock, [this] { return !full_.empty() || done_; });
      if (full_.empty()) return;  // done and drained
      b = std::move(full_.front());
      full_.pop_front();
    }
    for (const TraceItem& t : b->traces) write_trace(t);
    for (const Sample& s : b->samples) write_sample(s);
    b->traces.clear();
    b->samples.clear();
    {
      std::lock_guard lock(mu_);
      free_.push_back(std::move(b));
    }
    cv_.notify_all();
  }
}

std::string OutputWriter::close() {
  if (closed_) return {};
  closed_ = true;
  if (thread_.joinable()) {
    {
      std::lock_guard lock(mu_);
      full_.push_back(std::move(current_));
      done_ = true;
    }
    cv_.notify_all();
    thread_.join();
  }
  std::string err;
  for (OutputFile* f : {&trace_, &csv_}) {
    if (!f->is_open()) continue;
    f->close();
    if (f->error() != 0) {
      err += fmt::format("{}writing '{}' failed: {}", err.empty() ? "" : "; ", f->path(),
                         std::generic_category().message(f->error()));
    }
  }
  return err;
}

}  // namespace canmotion::rt
