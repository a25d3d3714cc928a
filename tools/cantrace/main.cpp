// cantrace: decode and inspect candump traces of a CANopen CiA 402 bus.
// Argument parsing and I/O only; decoding and analysis live in fieldbus/trace.

#include <fmt/format.h>
#include <poll.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "fieldbus/can/socketcan_bus.hpp"
#include "fieldbus/eds/eds.hpp"
#include "fieldbus/trace/analyzer.hpp"
#include "fieldbus/trace/decoder.hpp"
#include "fieldbus/trace/format.hpp"
#include "fieldbus/trace/reader.hpp"
#include "fieldbus/trace/report.hpp"
#include "fieldbus/trace/trace_config.hpp"
#include "plot.hpp"

namespace tr = canmotion::trace;
namespace can = canmotion::can;

namespace {

constexpr const char* kUsage = R"(cantrace - decode and inspect candump traces of a CANopen CiA 402 bus.

Usage: cantrace [options] [LOG|-]
  LOG is a candump log (candump -L / -l) or candump screen output (with or
  without -t a|d|z|A timestamps). Without LOG, or with '-', stdin is read.

Options:
         -l, --live IFACE    decode frames from a SocketCAN interface (CTRL-C stops)
         -c, --config FILE   canmotion YAML configuration: axis names, units, PDO layouts
         -s, --summary       print the analysis (state timelines, EMCYs, missing TPDOs,
                             following error, SYNC jitter, bus load, error frames)
         -q, --quiet         do not print the per-frame decode
         -j, --json          JSON output: one object per frame; with -s a summary object
             --csv DIR       write one CSV per node to DIR (time, controlword, statusword,
                             state, target, actual, following error)
             --plot FILE     draw positions, following error and SYNC jitter with gnuplot
                             (FILE.png or FILE.svg)
             --delta         relative timestamps are deltas to the previous frame (candump -t d)
             --period US     nominal SYNC period in microseconds for the jitter histogram
                             (default: config, else 0x1006 written in the trace, else the median)
             --bitrate BPS   bus bitrate for the bus load (default: config, else 1000000)
             --window MS     bus-load window in milliseconds (default 100)
             --lag N         following error: compare the actual position with the target
                             applied N SYNCs earlier (default 0; 1 for drives that sample
                             their position at SYNC before applying the new target)
         -n, --count N       stop after N frames
             --eds NODE=FILE name node NODE's objects (SDO transfers, PDO mappings) from
                             its EDS or DCF (CiA 306) and type their values by it;
                             repeat per node (default: the CiA 301/402 names)
             --check-args    check the options and exit (0 = valid); reads no input
         -h, --help          show this help

Exit status: 0 on success, 1 on errors (bad options, unreadable input, no frames).
Malformed lines are reported on stderr with their line number and skipped.

Examples:
  cantrace trace.log                          decode every frame
  candump -L vcan0 | cantrace                 decode live candump output
  cantrace -s -q trace.log                    analysis only
  cantrace -s --csv out --plot out/run.png -c axes.yaml trace.log
  cantrace --live vcan0 -s                    decode a live bus, summary at CTRL-C
  cantrace -j -s -q trace.log | jq .buses     summary for scripts
  cantrace --eds 2=config/examples/minimal-drive.eds trace.log
                                              node 2's objects by its EDS's names
)";

volatile std::sig_atomic_t g_stop = 0;
void on_signal(int) { g_stop = 1; }

struct Options {
  std::string input;
  std::string live;
  std::string config;
  bool summary = false;
  bool quiet = false;
  bool json = false;
  bool delta = false;
  std::string csv_dir;
  std::string plot;
  std::int64_t period_ns = 0;
  double bitrate = 0;
  std::int64_t window_ns = 100'000'000;
  std::uint32_t lag = 0;
  std::uint64_t count = 0;
  bool check_args = false;
  std::vector<std::pair<int, std::string>> eds;  // --eds NODE=FILE
};

[[noreturn]] void usage_error(const std::string& msg) {
  std::fprintf(stderr, "cantrace: %s\nTry 'cantrace --help' for more information.\n", msg.c_str());
  std::exit(1);
}

double number(const std::string& opt, const char* s) {
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(s, &end);
  if (errno != 0 || end == s || *end != '\0' || !(v > 0)) usage_error(opt + " needs a positive number, not '" + s + "'");
  return v;
}

Options parse_args(int argc, char** argv) {
  Options o;
  bool have_input = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> const char* {
      if (i + 1 >= argc) usage_error("option " + a + " needs a value");
      return argv[++i];
    };
    if (a == "-h" || a == "--help") {
      std::fputs(kUsage, stdout);
      std::exit(0);
    } else if (a == "-l" || a == "--live") {
      o.live = value();
    } else if (a == "-c" || a == "--config") {
      o.config = value();
    } else if (a == "--eds") {
      const std::string v = value();
      const std::size_t eq = v.find('=');
      char* end = nullptr;
      const long node = eq == std::string::npos ? 0 : std::strtol(v.c_str(), &end, 0);
      if (eq == std::string::npos || end != v.c_str() + eq || node < 1 || node > 127 || eq + 1 == v.size())
        usage_error("--eds '" + v + "': want NODE=FILE with NODE 1..127 (e.g. 2=drive.eds)");
      o.eds.emplace_back(static_cast<int>(node), v.substr(eq + 1));
    } else if (a == "-s" || a == "--summary") {
      o.summary = true;
    } else if (a == "-q" || a == "--quiet") {
      o.quiet = true;
    } else if (a == "-j" || a == "--json") {
      o.json = true;
    } else if (a == "--delta") {
      o.delta = true;
    } else if (a == "--check-args") {
      o.check_args = true;
    } else if (a == "--csv") {
      o.csv_dir = value();
    } else if (a == "--plot") {
      o.plot = value();
      if (!o.plot.ends_with(".png") && !o.plot.ends_with(".svg")) usage_error("--plot needs a FILE.png or FILE.svg name");
    } else if (a == "--period") {
      o.period_ns = static_cast<std::int64_t>(number(a, value()) * 1000.0 + 0.5);
    } else if (a == "--bitrate") {
      o.bitrate = number(a, value());
    } else if (a == "--window") {
      o.window_ns = static_cast<std::int64_t>(number(a, value()) * 1e6 + 0.5);
    } else if (a == "--lag") {
      const char* v = value();
      char* end = nullptr;
      const long n = std::strtol(v, &end, 10);
      if (end == v || *end != '\0' || n < 0 || n > static_cast<long>(tr::AnalyzerOptions::kMaxLag)) {
        usage_error(fmt::format("--lag needs a whole number of SYNC cycles 0..{}, not '{}'", tr::AnalyzerOptions::kMaxLag, v));
      }
      o.lag = static_cast<std::uint32_t>(n);
    } else if (a == "-n" || a == "--count") {
      o.count = static_cast<std::uint64_t>(number(a, value()));
    } else if (a.size() > 1 && a[0] == '-') {
      usage_error("unknown option '" + a + "'");
    } else {
      if (have_input) usage_error("only one LOG file can be given (got '" + o.input + "' and '" + a + "')");
      o.input = a;
      have_input = true;
    }
  }
  if (!o.live.empty() && have_input && o.input != "-") usage_error("--live and a LOG file exclude each other");
  return o;
}

/// One CAN interface seen in the trace: its own decoder and analyzer (node
/// ids are per bus).
struct Bus {
  std::string iface;
  std::unique_ptr<tr::Decoder> decoder;
  std::unique_ptr<tr::Analyzer> analyzer;
  std::array<std::FILE*, tr::kMaxNode + 1> csv{};
  std::array<std::string, tr::kMaxNode + 1> csv_path{};
};

/// Buses are few (candump takes at most 16 interfaces); a linear search is fine.
constexpr std::size_t kMaxBuses = 16;

class App {
 public:
  explicit App(Options o) : opt_(std::move(o)) {}

  int run();

 private:
  Bus* bus_for(std::string_view iface);
  void handle(Bus& bus, const can::TimedFrame& tf);
  void flush(bool force);
  int read_stream(std::FILE* in, const std::string& name);
  int read_live();
  int finish();

  Options opt_;
  std::optional<tr::TraceConfig> config_;
  std::vector<std::unique_ptr<Bus>> buses_;
  tr::FormatOptions fmt_opt_;
  std::vector<std::unique_ptr<canmotion::canopen::DeviceDictionary>> dictionaries_;  // --eds
  tr::NodeDictionaries names_{};
  tr::LineReader reader_{false};
  fmt::memory_buffer out_;
  fmt::memory_buffer csv_buf_;
  std::uint64_t frames_ = 0;
  std::string plot_dir_;
  bool plot_tmp_ = false;
};

Bus* App::bus_for(std::string_view iface) {
  for (auto& b : buses_) {
    if (b->iface == iface) return b.get();
  }
  if (buses_.size() >= kMaxBuses) return nullptr;
  auto b = std::make_unique<Bus>();
  b->iface = std::string(iface);
  b->decoder = std::make_unique<tr::Decoder>();
  tr::AnalyzerOptions ao;
  ao.nominal_period_ns = opt_.period_ns;
  ao.load_window_ns = opt_.window_ns;
  ao.ferr_lag_cycles = opt_.lag;
  ao.bitrate = opt_.bitrate > 0 ? opt_.bitrate : 1'000'000.0;
  if (config_) {
    if (ao.nominal_period_ns == 0 && config_->period_ns > 0) {
      ao.nominal_period_ns = config_->period_ns;
      ao.nominal_source = "config controller.period_ms";
    }
    for (const auto& cb : config_->buses) {
      if (opt_.bitrate <= 0 && cb.bitrate > 0 && (cb.interface == iface || config_->buses.size() == 1)) ao.bitrate = cb.bitrate;
    }
    for (const auto& n : config_->nodes) {
      // An axis applies to its bus's interface; with one bus (or "sim") to any interface.
      if (!n.interface.empty() && n.interface != iface && config_->buses.size() > 1) continue;
      for (std::uint8_t p = 1; p <= tr::kPdosPerDirection; ++p) {
        if (n.layouts.rpdo_set[p - 1]) b->decoder->set_config_layout(n.node, false, p, n.layouts.rpdo[p - 1]);
        if (n.layouts.tpdo_set[p - 1]) b->decoder->set_config_layout(n.node, true, p, n.layouts.tpdo[p - 1]);
      }
      ao.nodes[n.node].name = n.axis;
      ao.nodes[n.node].counts_per_unit = n.counts_per_unit;
      ao.nodes[n.node].unit = n.unit;
    }
  }
  b->analyzer = std::make_unique<tr::Analyzer>(std::move(ao));
  buses_.push_back(std::move(b));
  return buses_.back().get();
}

void App::flush(bool force) {
  if (!force && out_.size() < (1U << 16)) return;
  if (out_.size() != 0) std::fwrite(out_.data(), 1, out_.size(), stdout);
  out_.clear();
}

void App::handle(Bus& bus, const can::TimedFrame& tf) {
  const tr::Decoded& d = bus.decoder->decode(tf);
  ++frames_;
  if (!opt_.quiet) {
    if (opt_.json) {
      tr::format_json(d, bus.iface, fmt_opt_, out_);
    } else {
      tr::format_text(d, bus.iface, fmt_opt_, out_);
    }
    flush(false);
  }
  if (!opt_.summary && opt_.csv_dir.empty() && plot_dir_.empty()) return;
  tr::Sample s;
  if (!bus.analyzer->feed(d, *bus.decoder, &s)) return;
  const std::string& dir = !opt_.csv_dir.empty() ? opt_.csv_dir : plot_dir_;
  if (dir.empty()) return;
  std::FILE*& f = bus.csv[s.node];
  const double cpu = bus.analyzer->options().nodes[s.node].counts_per_unit;
  if (f == nullptr) {
    bus.csv_path[s.node] = fmt::format("{}/{}_node{}.csv", dir, bus.iface, s.node);
    f = std::fopen(bus.csv_path[s.node].c_str(), "w");
    if (f == nullptr) {
      std::fprintf(stderr, "cantrace: cannot write %s: %s\n", bus.csv_path[s.node].c_str(), std::strerror(errno));
      std::exit(1);
    }
    csv_buf_.clear();
    tr::format_csv_header(cpu > 0, csv_buf_);
    std::fwrite(csv_buf_.data(), 1, csv_buf_.size(), f);
  }
  csv_buf_.clear();
  tr::format_csv_row(s, tr::ReportOptions{fmt_opt_.time_digits, fmt_opt_.has_time}, cpu, csv_buf_);
  std::fwrite(csv_buf_.data(), 1, csv_buf_.size(), f);
}

int App::read_stream(std::FILE* in, const std::string& name) {
  std::vector<char> buf(1 << 20);
  std::size_t have = 0;
  std::uint64_t line_no = 0;
  std::uint64_t reported = 0;
  constexpr std::uint64_t kMaxReports = 50;
  bool eof = false;
  struct stat st {};
  const bool progress = ::isatty(STDERR_FILENO) && ::fstat(::fileno(in), &st) == 0 && S_ISREG(st.st_mode) &&
                        st.st_size > (64 << 20);
  std::uint64_t consumed = 0;
  std::uint64_t next_progress = 1ULL << 26;
  while (!eof && !g_stop) {
    const std::size_t n = std::fread(buf.data() + have, 1, buf.size() - have, in);
    if (n == 0) {
      if (std::ferror(in)) {
        std::fprintf(stderr, "cantrace: %s: read error: %s\n", name.c_str(), std::strerror(errno));
        return 1;
      }
      eof = true;
    }
    have += n;
    std::size_t start = 0;
    while (start < have) {
      const void* nl = std::memchr(buf.data() + start, '\n', have - start);
      std::size_t end = nl != nullptr ? static_cast<std::size_t>(static_cast<const char*>(nl) - buf.data()) : have;
      if (nl == nullptr && !eof) {
        if (start == 0 && have == buf.size()) {
          // A line longer than the buffer: not a candump line. Report and drop it.
          ++line_no;
          std::fprintf(stderr, "cantrace: %s:%llu: line longer than %zu bytes, skipped\n", name.c_str(),
                       static_cast<unsigned long long>(line_no), buf.size());
          have = 0;
          // Skip the rest of that line.
          int c = 0;
          while ((c = std::fgetc(in)) != EOF && c != '\n') {
          }
        }
        break;
      }
      ++line_no;
      const std::string_view line(buf.data() + start, end - start);
      start = end + 1;
      can::TimedFrame tf;
      std::string_view iface;
      const auto st_line = reader_.feed(line, tf, iface);
      if (st_line == tr::LineReader::Status::kFrame) {
        if (frames_ == 0) {
          fmt_opt_.has_time = reader_.has_time();
          fmt_opt_.time_digits = reader_.time_digits();
        }
        Bus* bus = bus_for(iface);
        if (bus == nullptr) {
          if (reported++ < kMaxReports) {
            std::fprintf(stderr, "cantrace: %s:%llu: more than %zu interfaces, frame skipped\n", name.c_str(),
                         static_cast<unsigned long long>(line_no), kMaxBuses);
          }
          continue;
        }
        handle(*bus, tf);
        if (opt_.count != 0 && frames_ >= opt_.count) {
          eof = true;
          break;
        }
      } else if (st_line != tr::LineReader::Status::kSkip) {
        if (reported++ < kMaxReports) {
          std::fprintf(stderr, "cantrace: %s:%llu: %s: %s, line skipped\n", name.c_str(),
                       static_cast<unsigned long long>(line_no),
                       st_line == tr::LineReader::Status::kUnsupported ? "unsupported" : "malformed", reader_.reason());
        } else if (reported == kMaxReports + 1) {
          std::fprintf(stderr, "cantrace: %s: further bad lines are counted, not listed\n", name.c_str());
        }
      }
    }
    consumed += start;
    std::memmove(buf.data(), buf.data() + start, have - start);
    have -= start;
    if (progress && consumed >= next_progress) {
      std::fprintf(stderr, "\rcantrace: %3.0f %% (%llu frames)", 100.0 * static_cast<double>(consumed) / static_cast<double>(st.st_size),
                   static_cast<unsigned long long>(frames_));
      next_progress += 1ULL << 26;
    }
  }
  if (progress) std::fputs("\r\033[K", stderr);
  flush(true);
  if (reader_.malformed() + reader_.unsupported() != 0) {
    std::fprintf(stderr, "cantrace: %s: %llu malformed and %llu unsupported lines skipped\n", name.c_str(),
                 static_cast<unsigned long long>(reader_.malformed()), static_cast<unsigned long long>(reader_.unsupported()));
  }
  if (reader_.backwards() != 0 && !opt_.delta) {
    std::fprintf(stderr,
                 "cantrace: %s: time went backwards %llu times; if this is 'candump -t d' output, use --delta\n",
                 name.c_str(), static_cast<unsigned long long>(reader_.backwards()));
  }
  return 0;
}

int App::read_live() {
  std::error_code ec;
  std::string detail;
  auto bus = can::SocketCanBus::open(opt_.live, {}, ec, &detail);
  if (!bus) {
    std::fprintf(stderr, "cantrace: --live %s: %s\n", opt_.live.c_str(), detail.empty() ? ec.message().c_str() : detail.c_str());
    return 1;
  }
  bus->set_rx_clock(can::SocketCanBus::RxClock::kRealtime);  // times as candump prints them
  Bus* b = bus_for(opt_.live);
  fmt_opt_.has_time = true;
  std::fprintf(stderr, "cantrace: listening on %s (CTRL-C stops)\n", opt_.live.c_str());
  std::array<can::TimedFrame, 256> frames{};
  std::array<can::BusEvent, 16> events{};
  while (!g_stop) {
    pollfd p{bus->fd(), POLLIN, 0};
    const int r = ::poll(&p, 1, 200);
    if (r < 0 && errno != EINTR) {
      std::fprintf(stderr, "cantrace: poll: %s\n", std::strerror(errno));
      return 1;
    }
    const std::size_t n = bus->receive(frames);
    for (std::size_t i = 0; i < n; ++i) handle(*b, frames[i]);
    const std::size_t ne = bus->poll_events(events);
    for (std::size_t i = 0; i < ne; ++i) {
      const can::BusEvent& e = events[i];
      std::uint32_t cls = 0;
      switch (e.kind) {
        case can::BusEvent::Kind::kErrorFrame: cls = e.detail; break;
        case can::BusEvent::Kind::kStateChanged: cls = e.state == can::BusState::kBusOff ? 0x40U : 0x04U; break;
        case can::BusEvent::Kind::kRestarted: cls = 0x100U; break;
        case can::BusEvent::Kind::kRxOverflow: cls = 0x04U; break;
        case can::BusEvent::Kind::kTxQueueFull: break;
        case can::BusEvent::Kind::kLinkDown: break;
        case can::BusEvent::Kind::kLinkUp: break;
      }
      if (cls == 0) continue;
      const tr::Decoded& d = b->decoder->decode_error(cls, e.t_ns);
      ++frames_;
      if (!opt_.quiet) (opt_.json ? tr::format_json : tr::format_text)(d, b->iface, fmt_opt_, out_);
      if (opt_.summary || !opt_.csv_dir.empty() || !plot_dir_.empty()) b->analyzer->feed(d, *b->decoder, nullptr);
    }
    flush(true);
    std::fflush(stdout);
    if (opt_.count != 0 && frames_ >= opt_.count) break;
  }
  return 0;
}

int App::finish() {
  for (auto& b : buses_) {
    b->analyzer->finish(*b->decoder);
    for (std::FILE*& f : b->csv) {
      if (f != nullptr) std::fclose(f);
      f = nullptr;
    }
  }
  const tr::ReportOptions ro{fmt_opt_.time_digits, fmt_opt_.has_time};
  if (opt_.summary) {
    if (opt_.json) {
      out_.append(std::string_view("{\"buses\":["));
      for (std::size_t i = 0; i < buses_.size(); ++i) {
        if (i != 0) out_.push_back(',');
        tr::format_summary_json(buses_[i]->iface, *buses_[i]->analyzer, ro, out_);
      }
      out_.append(std::string_view("]}\n"));
    } else {
      for (std::size_t i = 0; i < buses_.size(); ++i) {
        if (i != 0 || !opt_.quiet) out_.push_back('\n');
        tr::format_summary_text(buses_[i]->iface, *buses_[i]->analyzer, ro, out_);
      }
    }
    flush(true);
  }
  int rc = 0;
  if (!opt_.plot.empty()) {
    std::vector<PlotSeries> series;
    for (auto& b : buses_) {
      for (std::uint8_t n = 1; n <= tr::kMaxNode; ++n) {
        if (b->csv_path[n].empty()) continue;
        const tr::NodeSettings& s = b->analyzer->options().nodes[n];
        series.push_back(PlotSeries{b->iface, n, s.name, b->csv_path[n], s.counts_per_unit, s.unit});
      }
    }
    const tr::Analyzer* first = buses_.empty() ? nullptr : buses_.front()->analyzer.get();
    std::string err;
    if (!draw_plot(opt_.plot, series, first, buses_.empty() ? "" : buses_.front()->iface, ro, plot_dir_, err)) {
      std::fprintf(stderr, "cantrace: --plot %s: %s\n", opt_.plot.c_str(), err.c_str());
      rc = 1;
    }
  }
  if (plot_tmp_) std::filesystem::remove_all(plot_dir_);
  std::fflush(stdout);
  if (frames_ == 0) {
    std::fprintf(stderr, "cantrace: no CAN frames found in the input\n");
    return 1;
  }
  return rc;
}

int App::run() {
  for (const auto& [node, file] : opt_.eds) {
    try {
      dictionaries_.push_back(std::make_unique<canmotion::canopen::DeviceDictionary>(
          canmotion::eds::device_dictionary(canmotion::eds::load(file))));
    } catch (const std::exception& e) {
      std::fprintf(stderr, "cantrace: --eds %d=%s:\n%s\n", node, file.c_str(), e.what());
      return 1;
    }
    names_[static_cast<std::size_t>(node)] = dictionaries_.back().get();
    fmt_opt_.names = &names_;
  }
  if (!opt_.config.empty()) {
    try {
      config_ = tr::load_trace_config(opt_.config);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "cantrace: %s\n", e.what());
      return 1;
    }
  }
  reader_ = tr::LineReader(opt_.delta);
  if (!opt_.csv_dir.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(opt_.csv_dir, ec);
    if (ec) {
      std::fprintf(stderr, "cantrace: --csv %s: %s\n", opt_.csv_dir.c_str(), ec.message().c_str());
      return 1;
    }
  }
  if (!opt_.plot.empty()) {
    if (!opt_.csv_dir.empty()) {
      plot_dir_ = opt_.csv_dir;
    } else {
      std::string tmpl = (std::filesystem::temp_directory_path() / "cantrace-XXXXXX").string();
      if (::mkdtemp(tmpl.data()) == nullptr) {
        std::fprintf(stderr, "cantrace: cannot create a temporary folder: %s\n", std::strerror(errno));
        return 1;
      }
      plot_dir_ = tmpl;
      plot_tmp_ = true;
    }
  }
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  std::signal(SIGPIPE, SIG_IGN);
  int rc = 0;
  if (!opt_.live.empty()) {
    rc = read_live();
  } else if (opt_.input.empty() || opt_.input == "-") {
    rc = read_stream(stdin, "<stdin>");
  } else {
    std::FILE* f = std::fopen(opt_.input.c_str(), "rb");
    if (f == nullptr) {
      std::fprintf(stderr, "cantrace: %s: %s\n", opt_.input.c_str(), std::strerror(errno));
      return 1;
    }
    rc = read_stream(f, opt_.input);
    std::fclose(f);
  }
  const int rc2 = finish();
  return rc != 0 ? rc : rc2;
}

}  // namespace

int main(int argc, char** argv) {
  Options o = parse_args(argc, argv);
  if (o.check_args) {
    std::puts("cantrace: arguments OK; nothing was read");
    return 0;
  }
  App app(std::move(o));
  return app.run();
}
