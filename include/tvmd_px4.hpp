/* tvmd_px4.hpp: a header-only C++17 layer between PX4's uORB messages and the tvmd C interface
 * (tvmd.h). It converts frames (PX4: world NED, body FRD; tvmd: world and body z up), reads
 * the attitude as PX4's quaternion, maps the messages' fields, and runs the controller as a
 * cascade: the law at the position loop's rate, the attitude and the allocation at the rate
 * loop's.
 *
 * Frames. tvmd's world and body frames share PX4's x axis and flip y and z: a half turn about
 * x, T = diag(1, -1, -1) (T = T^-1). A vector v_ned is T v_ned in tvmd's world frame, a body
 * vector v_frd is T v_frd in tvmd's body frame, and the attitude R_ned (body FRD to NED) is
 * T R_ned T. The names below say the frame of every velocity: `velocity_ned` (world),
 * `velocity_body` (tvmd's state, body frame).
 *
 * uORB mapping (the templates read these fields, so PX4's own structs, or mirrors of them,
 * fit):
 *   vehicle_local_position   x, y, z (m, NED), vx, vy, vz (m/s, NED)
 *   vehicle_attitude         q[4] (w, x, y, z; body FRD to NED)
 *   vehicle_angular_velocity xyz[3] (rad/s, body FRD)
 *   trajectory_setpoint      position[3], velocity[3], acceleration[3] (NED)
 *   vehicle_torque_setpoint  xyz[3], normalized by the airframe's torque scale (FRD)
 *   vehicle_thrust_setpoint  xyz[3], normalized by the airframe's thrust scale (FRD)
 *   actuator_motors          control[12], normalized in [0, 1], NaN for not driven
 *   actuator_servos          control[8], normalized in [-1, 1], NaN for not driven
 * PX4's stock output path has 8 servo channels: at most four two-axis agents (eta_x, eta_y)
 * on one flight controller; larger teams need another servo output.
 *
 * The PX4 module px4/src/modules/tvmd_control (docs/px4-module.md) is built on this header;
 * its parameters are in its module.yaml. `Parameters` below are the scales of PX4's normalized
 * torque and thrust setpoints, for a module that keeps PX4's own controllers upstream.
 *
 * Thread safety: as tvmd.h, one task per controller handle; no heap, no exceptions. */
#ifndef TVMD_PX4_HPP
#define TVMD_PX4_HPP

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "tvmd.h"

namespace tvmd {
namespace px4 {

using Vec3 = std::array<float, 3>;
using Mat3 = std::array<float, 9>; /* row-major */

/* T v: NED to tvmd's z-up world, FRD to tvmd's body (and back: T is its own inverse). */
inline Vec3 flip(const float v[3]) { return Vec3{v[0], -v[1], -v[2]}; }

/* T R T for a row-major rotation: R_ned (FRD to NED) to tvmd's attitude, and back. */
inline Mat3 flip(const Mat3 &r) {
  const float s[3] = {1.0f, -1.0f, -1.0f};
  Mat3 out{};
  for (std::size_t i = 0; i < 3; ++i) {
    for (std::size_t j = 0; j < 3; ++j) {
      out[3 * i + j] = s[i] * r[3 * i + j] * s[j];
    }
  }
  return out;
}

/* PX4's quaternion (w, x, y, z) to its rotation matrix, row-major. */
inline Mat3 rotation_from_quaternion(const float q[4]) {
  const float w = q[0], x = q[1], y = q[2], z = q[3];
  return Mat3{1.0f - 2.0f * (y * y + z * z), 2.0f * (x * y - w * z),        2.0f * (x * z + w * y),
              2.0f * (x * y + w * z),        1.0f - 2.0f * (x * x + z * z), 2.0f * (y * z - w * x),
              2.0f * (x * z - w * y),        2.0f * (y * z + w * x),        1.0f - 2.0f * (x * x + y * y)};
}

/* A rotation matrix to a unit quaternion (w >= 0). */
inline std::array<float, 4> quaternion_from_rotation(const Mat3 &r) {
  const float trace = r[0] + r[4] + r[8];
  std::array<float, 4> q{};
  if (trace > 0.0f) {
    const float s = std::sqrt(trace + 1.0f) * 2.0f;
    q = {0.25f * s, (r[7] - r[5]) / s, (r[2] - r[6]) / s, (r[3] - r[1]) / s};
  } else if (r[0] > r[4] && r[0] > r[8]) {
    const float s = std::sqrt(1.0f + r[0] - r[4] - r[8]) * 2.0f;
    q = {(r[7] - r[5]) / s, 0.25f * s, (r[1] + r[3]) / s, (r[2] + r[6]) / s};
  } else if (r[4] > r[8]) {
    const float s = std::sqrt(1.0f + r[4] - r[0] - r[8]) * 2.0f;
    q = {(r[2] - r[6]) / s, (r[1] + r[3]) / s, 0.25f * s, (r[5] + r[7]) / s};
  } else {
    const float s = std::sqrt(1.0f + r[8] - r[0] - r[4]) * 2.0f;
    q = {(r[3] - r[1]) / s, (r[2] + r[6]) / s, (r[5] + r[7]) / s, 0.25f * s};
  }
  if (q[0] < 0.0f) {
    for (float &c : q) c = -c;
  }
  return q;
}

/* tvmd's attitude (body z-up to world z-up) from PX4's vehicle_attitude.q. */
inline Mat3 attitude_from_quaternion(const float q_ned[4]) {
  return flip(rotation_from_quaternion(q_ned));
}

/* R^T v for a row-major R. */
inline Vec3 transpose_times(const Mat3 &r, const Vec3 &v) {
  return Vec3{r[0] * v[0] + r[3] * v[1] + r[6] * v[2], r[1] * v[0] + r[4] * v[1] + r[7] * v[2],
              r[2] * v[0] + r[5] * v[1] + r[8] * v[2]};
}

/* R v for a row-major R. */
inline Vec3 times(const Mat3 &r, const Vec3 &v) {
  return Vec3{r[0] * v[0] + r[1] * v[1] + r[2] * v[2], r[3] * v[0] + r[4] * v[1] + r[5] * v[2],
              r[6] * v[0] + r[7] * v[1] + r[8] * v[2]};
}

/* tvmd's state from vehicle_local_position, vehicle_attitude and vehicle_angular_velocity:
 * position in the z-up world, the attitude, body rates and the velocity in the body frame
 * (tvmd's convention: velocity_body = R^T T velocity_ned). */
template <class LocalPosition, class Attitude, class AngularVelocity>
TvmdState state_from(const LocalPosition &lp, const Attitude &att, const AngularVelocity &av) {
  TvmdState s;
  std::memset(&s, 0, sizeof s);
  s.size = sizeof s;
  const float position_ned[3] = {lp.x, lp.y, lp.z};
  const float velocity_ned[3] = {lp.vx, lp.vy, lp.vz};
  const Vec3 position = flip(position_ned);
  const Mat3 r = attitude_from_quaternion(att.q);
  const Vec3 velocity_body = transpose_times(r, flip(velocity_ned));
  const Vec3 rates = flip(av.xyz);
  std::memcpy(s.position, position.data(), sizeof s.position);
  std::memcpy(s.attitude, r.data(), sizeof s.attitude);
  std::memcpy(s.angular_velocity, rates.data(), sizeof s.angular_velocity);
  std::memcpy(s.velocity, velocity_body.data(), sizeof s.velocity);
  return s;
}

/* tvmd's reference from a trajectory_setpoint (position, velocity, acceleration, NED) and the
 * full reference attitude as a PX4 quaternion (a multicopter setpoint carries only yaw; the
 * method tracks a full pose). Rates zero. */
template <class TrajectorySetpoint>
TvmdReference reference_from(const TrajectorySetpoint &sp, const float attitude_q_ned[4]) {
  TvmdReference r;
  std::memset(&r, 0, sizeof r);
  r.size = sizeof r;
  const Vec3 p = flip(sp.position), v = flip(sp.velocity), a = flip(sp.acceleration);
  const Mat3 att = attitude_from_quaternion(attitude_q_ned);
  std::memcpy(r.position, p.data(), sizeof r.position);
  std::memcpy(r.velocity, v.data(), sizeof r.velocity);
  std::memcpy(r.acceleration, a.data(), sizeof r.acceleration);
  std::memcpy(r.attitude, att.data(), sizeof r.attitude);
  return r;
}

/* The airframe's scales of a normalized setpoint of 1 (N m per axis, N). */
struct Parameters {
  float torque_scale[3];
  float thrust_scale;
};

/* vehicle_torque_setpoint / vehicle_thrust_setpoint (normalized, FRD) to tvmd's body wrench. */
template <class TorqueSetpoint, class ThrustSetpoint>
TvmdWrench wrench_from(const TorqueSetpoint &torque, const ThrustSetpoint &thrust,
                       const Parameters &p) {
  TvmdWrench w;
  std::memset(&w, 0, sizeof w);
  w.size = sizeof w;
  const float t[3] = {torque.xyz[0] * p.torque_scale[0], torque.xyz[1] * p.torque_scale[1],
                      torque.xyz[2] * p.torque_scale[2]};
  const float f[3] = {thrust.xyz[0] * p.thrust_scale, thrust.xyz[1] * p.thrust_scale,
                      thrust.xyz[2] * p.thrust_scale};
  const Vec3 tb = flip(t), fb = flip(f);
  std::memcpy(w.torque, tb.data(), sizeof w.torque);
  std::memcpy(w.force, fb.data(), sizeof w.force);
  return w;
}

/* The law's body wrench as normalized PX4 setpoints (FRD): the inverse of `wrench_from`. */
template <class TorqueSetpoint, class ThrustSetpoint>
void setpoints_from(const TvmdLawOutput &law, const Parameters &p, TorqueSetpoint &torque,
                    ThrustSetpoint &thrust) {
  const Vec3 t = flip(law.torque), f = flip(law.force);
  for (std::size_t i = 0; i < 3; ++i) {
    torque.xyz[i] = t[i] / p.torque_scale[i];
    thrust.xyz[i] = f[i] / p.thrust_scale;
  }
}

/* actuator_motors (12 channels) and actuator_servos (8) from tvmd's mapped outputs; channels
 * the map does not drive stay NaN, PX4's "not driven". */
template <class Motors, class Servos>
void actuators_from(const TvmdActuatorOutputs &out, Motors &motors, Servos &servos) {
  for (std::size_t i = 0; i < 12; ++i) motors.control[i] = out.motors[i];
  for (std::size_t i = 0; i < 8; ++i) servos.control[i] = out.servos[i];
}

/* One stage's statuses, so that none is swallowed: the latest call's, the latest that was not
 * TVMD_OK, how many were not since creation and since the stage last succeeded (a flight
 * stack raises a failsafe when `consecutive` grows). */
struct StageReport {
  TvmdStatus last = TVMD_OK;
  TvmdStatus last_error = TVMD_OK;
  std::uint32_t errors = 0;
  std::uint32_t consecutive = 0;

  void record(TvmdStatus status) {
    last = status;
    if (status == TVMD_OK) {
      consecutive = 0;
    } else {
      last_error = status;
      ++errors;
      ++consecutive;
    }
  }
};

/* The controller as PX4's cascade: `position` at the position loop's rate runs the law stage
 * (tvmd_law: the planned attitude R_d and the body force, kept as an inertial force);
 * `attitude_and_allocate` at the rate loop's rate takes the torque for the kept R_d from the
 * newest state (tvmd_attitude), the kept inertial force in the newest body frame, and
 * allocates them (tvmd_allocate).
 *
 * A bad sample does not stop it. A refused law period keeps the last good law output (R_d,
 * the force, the reference), so the fast loop keeps flying on it; a refused fast period
 * (a NaN gyro sample, a refused allocation, no law output yet) still writes `out`: the held
 * commands of the C interface (`tvmd_allocate`'s fallback), never an unwritten or zero
 * output. Every status that is not TVMD_OK is returned and counted in `report()`. */
class Cascade {
 public:
  struct Report {
    StageReport law;      /* `position`: tvmd_law */
    StageReport attitude; /* `attitude_and_allocate`: tvmd_attitude (and "no law output yet") */
    StageReport allocate; /* `attitude_and_allocate`: tvmd_allocate */
    StageReport compensation; /* `attitude_and_allocate`: tvmd_compensation */
  };

  explicit Cascade(TvmdController *controller) : controller_(controller) {
    std::memset(&law_, 0, sizeof law_);
    law_.size = sizeof law_;
    std::memset(&attitude_, 0, sizeof attitude_);
    attitude_.size = sizeof attitude_;
    std::memset(&requested_, 0, sizeof requested_);
    requested_.size = sizeof requested_;
    force_world_.fill(0.0f);
    std::memset(&compensation_, 0, sizeof compensation_);
    compensation_.size = sizeof compensation_;
    for (std::size_t i = 0; i < 3; ++i) compensation_.force[i] = compensation_.torque[i] = NAN;
  }

  /* The law stage. On an error the last good law output stays in force. */
  TvmdStatus position(const TvmdState &state, const TvmdReference &reference) {
    TvmdLawOutput law;
    std::memset(&law, 0, sizeof law);
    law.size = sizeof law;
    const TvmdStatus status = tvmd_law(controller_, &state, &reference, &law);
    report_.law.record(status);
    if (status == TVMD_OK) {
      law_ = law;
      Mat3 r;
      std::memcpy(r.data(), state.attitude, sizeof state.attitude);
      force_world_ = times(r, Vec3{law_.force[0], law_.force[1], law_.force[2]});
      reference_ = reference;
      have_law_ = true;
    }
    return status;
  }

  /* The attitude stage and the allocation. `out` is always written (when usable): the new
   * commands, or on an error the held ones with `out->status` the error. */
  TvmdStatus attitude_and_allocate(const TvmdState &state, TvmdAllocationOutput *out) {
    if (!have_law_) return held(TVMD_ERR_NOT_INITIALIZED, out);
    std::memset(&attitude_, 0, sizeof attitude_);
    attitude_.size = sizeof attitude_;
    const TvmdStatus status =
        tvmd_attitude(controller_, &state, law_.planned_attitude, &reference_, &attitude_);
    if (status != TVMD_OK) return held(status, out);
    report_.attitude.record(status);
    Mat3 r;
    std::memcpy(r.data(), state.attitude, sizeof state.attitude);
    const Vec3 force_body = transpose_times(r, force_world_);
    std::memcpy(requested_.torque, attitude_.torque, sizeof requested_.torque);
    std::memcpy(requested_.force, force_body.data(), sizeof requested_.force);
    /* On an error tvmd_allocate itself writes the held commands. */
    const TvmdStatus allocated = tvmd_allocate(controller_, &requested_, out);
    report_.allocate.record(allocated);
    /* The allocation after a law period updates the offset-free state: read it now. */
    report_.compensation.record(tvmd_compensation(controller_, &compensation_));
    return allocated;
  }

  /* The last good law output (zero before the first). */
  const TvmdLawOutput &law() const { return law_; }
  /* The latest fast period's attitude stage (NaN when it was refused) and the wrench it asked
   * the allocation for (the last one that reached it). */
  const TvmdAttitudeOutput &attitude() const { return attitude_; }
  const TvmdWrench &requested() const { return requested_; }
  bool has_law() const { return have_law_; }
  /* The offset-free compensation (force N in tvmd's world frame, torque N m in its body frame)
   * after the latest fast period that reached the allocation: what the next law period adds
   * to its request; zero without an offset-free action and while landed, NaN before the first
   * allocation. `tvmd_step`'s `compensation_*` of the same period. */
  const TvmdCompensation &compensation() const { return compensation_; }
  const Report &report() const { return report_; }

 private:
  /* The held commands into `out` (tvmd_allocate without a wrench writes them and changes
   * nothing), with the stage's error as the status. */
  TvmdStatus held(TvmdStatus status, TvmdAllocationOutput *out) {
    report_.attitude.record(status);
    if (out == nullptr) return status;
    const TvmdStatus fallback = tvmd_allocate(controller_, nullptr, out);
    if (fallback != TVMD_ERR_NULL_POINTER) {
      /* The handle itself was refused (not created, corrupted, `out` of another size). */
      report_.allocate.record(fallback);
      return fallback;
    }
    out->status = status;
    return status;
  }

  TvmdController *controller_;
  TvmdLawOutput law_;
  TvmdAttitudeOutput attitude_;
  TvmdWrench requested_;
  TvmdReference reference_{};
  Vec3 force_world_{};
  TvmdCompensation compensation_;
  bool have_law_ = false;
  Report report_{};
};

} /* namespace px4 */
} /* namespace tvmd */

#endif /* TVMD_PX4_HPP */
