#pragma once
/// \file
/// The rows of canmotiond's --csv file (one per axis per cycle, from the
/// controller's telemetry ring), formatted without stdio: the same bytes as
/// the printf format they replace,
///     "%llu,%.6f,%s,%.6f,%.6f,%.6f,%.6f,%u,%u\n"
/// (tests/controller/telemetry_csv_test.cpp checks it against snprintf).
/// Realtime-safe, but meant for the non-RT thread that drains the ring.

#include <cstddef>
#include <string_view>

#include "rt/controller/controller.hpp"
#include "rt/text_output.hpp"

namespace canmotion::rt {

/// The header line of the --csv file, with its newline.
inline constexpr std::string_view kTelemetryCsvHeader =
    "cycle,time,axis,cmd_pos,act_pos,cmd_vel,act_vel,motion_status,axis_status\n";

/// Bytes format_telemetry_csv_row() may write for an axis name of `name_len`
/// characters: a 20-digit cycle, five %.6f values, two 10-digit integers,
/// eight commas and the newline.
constexpr std::size_t telemetry_csv_row_max(std::size_t name_len) noexcept {
  return 20 + 5 * kFixed6Max + name_len + 2 * 10 + 8 + 1;
}

/// Writes the row of `s` (time = s.cycle x period_s, axis name `axis`) with
/// its newline into `out`, which holds telemetry_csv_row_max(axis.size())
/// bytes; returns the end. Realtime-safe.
char* format_telemetry_csv_row(char* out, const Sample& s, double period_s, std::string_view axis) noexcept;

}  // namespace canmotion::rt
