#include "rt/controller/telemetry_csv.hpp"

#include <cstring>

namespace canmotion::rt {

char* format_telemetry_csv_row(char* out, const Sample& s, double period_s, std::string_view axis) noexcept {
  char* p = format_u64(out, s.cycle);
  *p++ = ',';
  p = format_fixed6(p, static_cast<double>(s.cycle) * period_s);
  *p++ = ',';
  if (!axis.empty()) std::memcpy(p, axis.data(), axis.size());
  p += axis.size();
  for (const double v : {s.cmd_pos, s.act_pos, s.cmd_vel, s.act_vel}) {
    *p++ = ',';
    p = format_fixed6(p, v);
  }
  *p++ = ',';
  p = format_u64(p, s.motion_status);
  *p++ = ',';
  p = format_u64(p, s.axis_status);
  *p++ = '\n';
  return p;
}

}  // namespace canmotion::rt
