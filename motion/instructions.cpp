#include "motion/instructions.hpp"

#include <cmath>

namespace canmotion::motion {
namespace {

/// Operand positions, looked up once by name in the signature table.
struct Pos {
  int mas_type, mas_chg_d, mas_d, mas_du, mas_chg_j, mas_j, mas_ju;
  int maj_dir, maj_speed;
  int mam_type, mam_pos, mam_speed, mam_ed, mam_cd;
  int mag_dir, mag_ratio, mag_sc, mag_mc, mag_ref, mag_fmt, mag_clutch, mag_acc, mag_accu;
  int mcd_type, mcd_cs, mcd_s, mcd_ca, mcd_a, mcd_cd, mcd_d, mcd_cja, mcd_ja, mcd_cjd, mcd_jd, mcd_su, mcd_au, mcd_du, mcd_ju;
  int mrp_type, mrp_sel, mrp_pos;
  int mgs_mode;
  int mccp_cam, mccp_len, mccp_ss, mccp_es, mccp_prof;
  int mapc_dir, mapc_prof, mapc_ss, mapc_ms, mapc_em, mapc_es, mapc_mlp, mapc_clp, mapc_ref, mapc_md;
  int matc_dir, matc_prof, matc_ds, matc_ts, matc_em, matc_es, matc_lp, matc_ld, matc_im;
  int mdac_type, mdac_ref;
  int mds_speed, mds_units;
};

const Pos& pos() noexcept {
  static const Pos p = [] {
    auto i = [](Instr in, const char* n) { return operand_index(in, n); };
    Pos q{};
    q.mas_type = i(Instr::MAS, "StopType"); q.mas_chg_d = i(Instr::MAS, "ChangeDecel"); q.mas_d = i(Instr::MAS, "DecelRate");
    q.mas_du = i(Instr::MAS, "DecelUnits"); q.mas_chg_j = i(Instr::MAS, "ChangeDecelJerk"); q.mas_j = i(Instr::MAS, "DecelJerk");
    q.mas_ju = i(Instr::MAS, "JerkUnits");
    q.maj_dir = i(Instr::MAJ, "Direction"); q.maj_speed = i(Instr::MAJ, "Speed");
    q.mam_type = i(Instr::MAM, "MoveType"); q.mam_pos = i(Instr::MAM, "Position"); q.mam_speed = i(Instr::MAM, "Speed");
    q.mam_ed = i(Instr::MAM, "EventDistance"); q.mam_cd = i(Instr::MAM, "CalculatedData");
    q.mag_dir = i(Instr::MAG, "Direction"); q.mag_ratio = i(Instr::MAG, "Ratio"); q.mag_sc = i(Instr::MAG, "SlaveCounts");
    q.mag_mc = i(Instr::MAG, "MasterCounts"); q.mag_ref = i(Instr::MAG, "MasterReference");
    q.mag_fmt = i(Instr::MAG, "RatioFormat"); q.mag_clutch = i(Instr::MAG, "Clutch"); q.mag_acc = i(Instr::MAG, "AccelRate");
    q.mag_accu = i(Instr::MAG, "AccelUnits");
    q.mcd_type = i(Instr::MCD, "MotionType"); q.mcd_cs = i(Instr::MCD, "ChangeSpeed"); q.mcd_s = i(Instr::MCD, "Speed");
    q.mcd_ca = i(Instr::MCD, "ChangeAccel"); q.mcd_a = i(Instr::MCD, "AccelRate"); q.mcd_cd = i(Instr::MCD, "ChangeDecel");
    q.mcd_d = i(Instr::MCD, "DecelRate"); q.mcd_cja = i(Instr::MCD, "ChangeAccelJerk"); q.mcd_ja = i(Instr::MCD, "AccelJerk");
    q.mcd_cjd = i(Instr::MCD, "ChangeDecelJerk"); q.mcd_jd = i(Instr::MCD, "DecelJerk"); q.mcd_su = i(Instr::MCD, "SpeedUnits");
    q.mcd_au = i(Instr::MCD, "AccelUnits"); q.mcd_du = i(Instr::MCD, "DecelUnits"); q.mcd_ju = i(Instr::MCD, "JerkUnits");
    q.mrp_type = i(Instr::MRP, "Type"); q.mrp_sel = i(Instr::MRP, "PositionSelect"); q.mrp_pos = i(Instr::MRP, "Position");
    q.mgs_mode = i(Instr::MGS, "StopMode");
    q.mccp_cam = i(Instr::MCCP, "Cam"); q.mccp_len = i(Instr::MCCP, "Length"); q.mccp_ss = i(Instr::MCCP, "StartSlope");
    q.mccp_es = i(Instr::MCCP, "EndSlope"); q.mccp_prof = i(Instr::MCCP, "CamProfile");
    q.mapc_dir = i(Instr::MAPC, "Direction"); q.mapc_prof = i(Instr::MAPC, "CamProfile");
    q.mapc_ss = i(Instr::MAPC, "SlaveScaling"); q.mapc_ms = i(Instr::MAPC, "MasterScaling");
    q.mapc_em = i(Instr::MAPC, "ExecutionMode"); q.mapc_es = i(Instr::MAPC, "ExecutionSchedule");
    q.mapc_mlp = i(Instr::MAPC, "MasterLockPosition"); q.mapc_clp = i(Instr::MAPC, "CamLockPosition");
    q.mapc_ref = i(Instr::MAPC, "MasterReference"); q.mapc_md = i(Instr::MAPC, "MasterDirection");
    q.matc_dir = i(Instr::MATC, "Direction"); q.matc_prof = i(Instr::MATC, "CamProfile");
    q.matc_ds = i(Instr::MATC, "DistanceScaling"); q.matc_ts = i(Instr::MATC, "TimeScaling");
    q.matc_em = i(Instr::MATC, "ExecutionMode"); q.matc_es = i(Instr::MATC, "ExecutionSchedule");
    q.matc_lp = i(Instr::MATC, "LockPosition"); q.matc_ld = i(Instr::MATC, "LockDirection");
    q.matc_im = i(Instr::MATC, "InstructionMode");
    q.mdac_type = i(Instr::MDAC, "MotionType"); q.mdac_ref = i(Instr::MDAC, "MasterReference");
    q.mds_speed = i(Instr::MDS, "Speed"); q.mds_units = i(Instr::MDS, "SpeedUnits");
    return q;
  }();
  return p;
}

struct R {
  const Request& r;
  double d(int i) const noexcept { return r.op[static_cast<std::size_t>(i)].value; }
  std::uint8_t u8(int i) const noexcept { return static_cast<std::uint8_t>(static_cast<int>(d(i))); }
  bool yes(int i) const noexcept { return static_cast<int>(d(i)) == 1; }
  std::uint16_t ref(int i) const noexcept { return r.op[static_cast<std::size_t>(i)].ref; }
  std::int32_t i32(int i) const noexcept { return static_cast<std::int32_t>(d(i)); }
};

Dynamics dynamics(const R& q, int s) noexcept {
  Dynamics y;
  y.first_operand = s;
  y.speed = q.d(s);
  y.speed_units = q.u8(s + 1);
  y.accel = q.d(s + 2);
  y.accel_units = q.u8(s + 3);
  y.decel = q.d(s + 4);
  y.decel_units = q.u8(s + 5);
  y.profile = static_cast<ProfileType>(q.u8(s + 6));
  y.accel_jerk = q.d(s + 7);
  y.decel_jerk = q.d(s + 8);
  y.jerk_units = q.u8(s + 9);
  y.merge = static_cast<Merge>(q.u8(s + 10));
  y.merge_speed = static_cast<MergeSpeed>(q.u8(s + 11));
  y.lock_position = q.d(s + 12);
  y.lock_direction = static_cast<LockDirection>(q.u8(s + 13));
  return y;
}

}  // namespace

void init_instruction_tables() noexcept { (void)pos(); }

Params decode(const Request& r) noexcept {
  const Pos& P = pos();
  const R q{r};
  switch (r.instr) {
    case Instr::MSO: return MsoParams{q.ref(0)};
    case Instr::MSF: return MsfParams{q.ref(0)};
    case Instr::MASD: return MasdParams{q.ref(0)};
    case Instr::MASR: return MasrParams{q.ref(0)};
    case Instr::MAFR: return MafrParams{q.ref(0)};
    case Instr::MAH: return MahParams{q.ref(0)};
    case Instr::MAS:
      return MasParams{q.ref(0), static_cast<StopType>(q.u8(P.mas_type)), q.yes(P.mas_chg_d), q.d(P.mas_d),
                       q.u8(P.mas_du), q.yes(P.mas_chg_j), q.d(P.mas_j), q.u8(P.mas_ju)};
    case Instr::MAJ: return MajParams{q.ref(0), q.yes(P.maj_dir), dynamics(q, P.maj_speed)};
    case Instr::MAM: {
      MamParams m;
      m.axis = q.ref(0);
      m.move_type = static_cast<MoveType>(q.u8(P.mam_type));
      m.position = q.d(P.mam_pos);
      m.dyn = dynamics(q, P.mam_speed);
      m.event_distance = q.ref(P.mam_ed);
      m.calculated_data = q.ref(P.mam_cd);
      return m;
    }
    case Instr::MAG: {
      MagParams m;
      m.slave = q.ref(0);
      m.master = q.ref(1);
      m.direction = static_cast<CamDirection>(q.u8(P.mag_dir));
      m.ratio = q.d(P.mag_ratio);
      m.slave_counts = q.d(P.mag_sc);
      m.master_counts = q.d(P.mag_mc);
      m.master_reference = static_cast<MasterReference>(q.u8(P.mag_ref));
      m.fractional = q.yes(P.mag_fmt);
      m.clutch = q.u8(P.mag_clutch) == 0;
      m.accel_rate = q.d(P.mag_acc);
      m.accel_units = q.u8(P.mag_accu);
      return m;
    }
    case Instr::MCD: {
      McdParams m;
      m.axis = q.ref(0);
      m.jog = q.u8(P.mcd_type) == 0;
      m.change_speed = q.yes(P.mcd_cs); m.speed = q.d(P.mcd_s);
      m.change_accel = q.yes(P.mcd_ca); m.accel = q.d(P.mcd_a);
      m.change_decel = q.yes(P.mcd_cd); m.decel = q.d(P.mcd_d);
      m.change_accel_jerk = q.yes(P.mcd_cja); m.accel_jerk = q.d(P.mcd_ja);
      m.change_decel_jerk = q.yes(P.mcd_cjd); m.decel_jerk = q.d(P.mcd_jd);
      m.speed_units = q.u8(P.mcd_su); m.accel_units = q.u8(P.mcd_au);
      m.decel_units = q.u8(P.mcd_du); m.jerk_units = q.u8(P.mcd_ju);
      return m;
    }
    case Instr::MRP: return MrpParams{q.ref(0), q.yes(P.mrp_type), q.yes(P.mrp_sel), q.d(P.mrp_pos)};
    case Instr::MGS: return MgsParams{q.ref(0), static_cast<GroupStopMode>(q.u8(P.mgs_mode))};
    case Instr::MGSD: return MgsdParams{q.ref(0)};
    case Instr::MGSR: return MgsrParams{q.ref(0)};
    case Instr::MCCP:
      return MccpParams{q.ref(P.mccp_cam), q.i32(P.mccp_cam), q.i32(P.mccp_len), q.d(P.mccp_ss), q.d(P.mccp_es),
                        q.ref(P.mccp_prof)};
    case Instr::MAPC: {
      MapcParams m;
      m.slave = q.ref(0);
      m.master = q.ref(1);
      m.direction = static_cast<CamDirection>(q.u8(P.mapc_dir));
      m.cam_profile = q.ref(P.mapc_prof);
      m.slave_scaling = q.d(P.mapc_ss);
      m.master_scaling = q.d(P.mapc_ms);
      m.execution_mode = q.u8(P.mapc_em);
      m.execution_schedule = q.u8(P.mapc_es);
      m.master_lock_position = q.d(P.mapc_mlp);
      m.cam_lock_position = q.d(P.mapc_clp);
      m.master_reference = static_cast<MasterReference>(q.u8(P.mapc_ref));
      m.master_direction = q.u8(P.mapc_md);
      return m;
    }
    case Instr::MATC: {
      MatcParams m;
      m.axis = q.ref(0);
      m.direction = static_cast<CamDirection>(q.u8(P.matc_dir));
      m.cam_profile = q.ref(P.matc_prof);
      m.distance_scaling = q.d(P.matc_ds);
      m.time_scaling = q.d(P.matc_ts);
      m.execution_mode = q.u8(P.matc_em);
      m.execution_schedule = q.u8(P.matc_es);
      m.lock_position = q.d(P.matc_lp);
      m.lock_direction = static_cast<LockDirection>(q.u8(P.matc_ld));
      m.master_driven = q.yes(P.matc_im);
      return m;
    }
    case Instr::MDAC:
      return MdacParams{q.ref(0), q.ref(1), q.u8(P.mdac_type), static_cast<MasterReference>(q.u8(P.mdac_ref))};
    case Instr::MDS: return MdsParams{q.ref(0), q.d(P.mds_speed), q.u8(P.mds_units) == 0};
    default: return CoordinatedParams{r.instr};
  }
}

}  // namespace canmotion::motion
