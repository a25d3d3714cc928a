// The per-node CSV rows (--csv, --plot). The summaries are in report_text.cpp
// and report_json.cpp.
#include "fieldbus/trace/report.hpp"

#include "fieldbus/trace/format.hpp"
#include "fieldbus/trace/report_detail.hpp"

namespace canmotion::trace {

using detail::Out;
using detail::put;

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
