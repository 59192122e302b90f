// The C++ test of the PX4 adapter (include/tvmd_px4.hpp), compiled with -std=c++17 -Wall
// -Wextra -Werror -Wpedantic -Wold-style-cast by scripts/ffi.sh: frame and quaternion round
// trips, the uORB mapping of a hover against the C state built by hand (same commands, bit for
// bit), and a flight of hover and the saturating tilt through the cascade (the law at 50 Hz,
// the attitude and the allocation at 250 Hz) against the full step at 250 Hz: the same
// planned roll within 1e-3 rad; and the cascade through bad samples (a NaN gyro sample gets
// the held commands, a refused law period keeps the last good law output); the offset-free
// compensation read through the cascade converges to an unmodelled force's negative.
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "tvmd_px4.hpp"

namespace {

int checks = 0, failed = 0;

void check(bool ok, const char *what, int line) {
  ++checks;
  if (!ok) {
    ++failed;
    std::fprintf(stderr, "px4_test.cpp:%d: check failed: %s\n", line, what);
  }
}
#define CHECK(cond) check((cond), #cond, __LINE__)

// Mirrors of the uORB messages' fields the adapter reads.
struct vehicle_local_position_s { float x, y, z, vx, vy, vz; };
struct vehicle_attitude_s { float q[4]; };
struct vehicle_angular_velocity_s { float xyz[3]; };
struct trajectory_setpoint_s { float position[3], velocity[3], acceleration[3]; };
struct vehicle_torque_setpoint_s { float xyz[3]; };
struct vehicle_thrust_setpoint_s { float xyz[3]; };

using tvmd::px4::Mat3;
using tvmd::px4::Vec3;

bool near(float a, float b, float tol) { return std::fabs(a - b) <= tol; }

void test_frames() {
  const float qs[3][4] = {{1.0f, 0.0f, 0.0f, 0.0f},
                          {0.70710678f, 0.0f, 0.0f, 0.70710678f},
                          {0.5f, 0.5f, -0.5f, 0.5f}};
  for (const auto &q : qs) {
    const Mat3 r = tvmd::px4::rotation_from_quaternion(q);
    const auto back = tvmd::px4::quaternion_from_rotation(r);
    for (std::size_t i = 0; i < 4; ++i) CHECK(near(back[i], q[i], 1e-6f));
    const Mat3 twice = tvmd::px4::flip(tvmd::px4::flip(r));
    CHECK(std::memcmp(twice.data(), r.data(), sizeof r) == 0);
  }
  // Nose east in NED (yaw +90 deg) is nose toward -y in tvmd's world (y west, z up).
  const Mat3 east = tvmd::px4::attitude_from_quaternion(qs[1]);
  CHECK(near(east[0], 0.0f, 1e-6f) && near(east[3], -1.0f, 1e-6f) && near(east[6], 0.0f, 1e-6f));
  vehicle_local_position_s lp{1.0f, 2.0f, -3.0f, 1.0f, 0.0f, -2.0f};
  vehicle_attitude_s att{{1.0f, 0.0f, 0.0f, 0.0f}};
  vehicle_angular_velocity_s av{{0.1f, 0.2f, 0.3f}};
  const TvmdState s = tvmd::px4::state_from(lp, att, av);
  CHECK(s.position[0] == 1.0f && s.position[1] == -2.0f && s.position[2] == 3.0f);
  // Level, flying north and climbing at 2 m/s: body velocity (1, 0, 2) in tvmd's frame.
  CHECK(s.velocity[0] == 1.0f && s.velocity[1] == 0.0f && s.velocity[2] == 2.0f);
  CHECK(s.angular_velocity[0] == 0.1f && s.angular_velocity[1] == -0.2f &&
        s.angular_velocity[2] == -0.3f);
}

TvmdController whole_storage, staged_storage;

TvmdConfig paper() {
  TvmdConfig c;
  std::memset(&c, 0, sizeof c);
  c.size = sizeof c;
  CHECK(tvmd_config_paper(&c) == TVMD_OK);
  c.period = 0.004f;
  return c;
}

void test_hover_matches_c() {
  TvmdConfig config = paper();
  CHECK(tvmd_create(&whole_storage, sizeof whole_storage, &config) == TVMD_OK);
  CHECK(tvmd_create(&staged_storage, sizeof staged_storage, &config) == TVMD_OK);
  vehicle_local_position_s lp{0.1f, 0.0f, -1.5f, 0.0f, 0.0f, 0.0f};
  vehicle_attitude_s att{{1.0f, 0.0f, 0.0f, 0.0f}};
  vehicle_angular_velocity_s av{{0.0f, 0.0f, 0.0f}};
  trajectory_setpoint_s sp{{0.0f, 0.0f, -1.5f}, {0.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 0.0f}};
  const float level[4] = {1.0f, 0.0f, 0.0f, 0.0f};
  const TvmdState via = tvmd::px4::state_from(lp, att, av);
  const TvmdReference ref_via = tvmd::px4::reference_from(sp, level);
  TvmdState direct;
  std::memset(&direct, 0, sizeof direct);
  direct.size = sizeof direct;
  direct.position[0] = 0.1f;
  direct.position[2] = 1.5f;
  direct.attitude[0] = direct.attitude[4] = direct.attitude[8] = 1.0f;
  TvmdReference ref_direct;
  std::memset(&ref_direct, 0, sizeof ref_direct);
  ref_direct.size = sizeof ref_direct;
  ref_direct.position[2] = 1.5f;
  ref_direct.attitude[0] = ref_direct.attitude[4] = ref_direct.attitude[8] = 1.0f;
  TvmdOutput a, b;
  std::memset(&a, 0, sizeof a);
  std::memset(&b, 0, sizeof b);
  a.size = b.size = sizeof a;
  CHECK(tvmd_step(&whole_storage, &via, &ref_via, &a) == TVMD_OK);
  CHECK(tvmd_step(&staged_storage, &direct, &ref_direct, &b) == TVMD_OK);
  CHECK(std::memcmp(a.commands, b.commands, sizeof a.commands) == 0);
  // The law's wrench as PX4 setpoints and back.
  TvmdLawOutput law;
  std::memset(&law, 0, sizeof law);
  law.size = sizeof law;
  CHECK(tvmd_law(&whole_storage, &via, &ref_via, &law) == TVMD_OK);
  const tvmd::px4::Parameters p{{2.0f, 2.0f, 1.0f}, 55.0f};
  vehicle_torque_setpoint_s torque{};
  vehicle_thrust_setpoint_s thrust{};
  tvmd::px4::setpoints_from(law, p, torque, thrust);
  CHECK(thrust.xyz[2] < 0.0f);  // FRD: up is -z.
  const TvmdWrench w = tvmd::px4::wrench_from(torque, thrust, p);
  for (std::size_t i = 0; i < 3; ++i) {
    CHECK(near(w.torque[i], law.torque[i], 1e-5f));
    CHECK(near(w.force[i], law.force[i], 1e-4f));
  }
}

// A rigid body under the allocated body wrench, 1 kHz, zero-order hold.
struct Body {
  Vec3 x{0.0f, 0.0f, 1.5f}, v{0.0f, 0.0f, 0.0f}, w{0.0f, 0.0f, 0.0f};
  Mat3 r{1.0f, 0.0f, 0.0f, 0.0f, 1.0f, 0.0f, 0.0f, 0.0f, 1.0f};
};

TvmdState state_of(const Body &b) {
  TvmdState s;
  std::memset(&s, 0, sizeof s);
  s.size = sizeof s;
  const Vec3 vb = tvmd::px4::transpose_times(b.r, b.v);
  std::memcpy(s.position, b.x.data(), sizeof s.position);
  std::memcpy(s.attitude, b.r.data(), sizeof s.attitude);
  std::memcpy(s.angular_velocity, b.w.data(), sizeof s.angular_velocity);
  std::memcpy(s.velocity, vb.data(), sizeof s.velocity);
  return s;
}

void advance(Body &b, const float torque[3], const float force[3], float mass, const Vec3 &j,
             float dt) {
  const Vec3 fw = tvmd::px4::times(b.r, Vec3{force[0], force[1], force[2]});
  for (std::size_t i = 0; i < 3; ++i) b.v[i] += dt * (fw[i] / mass - (i == 2 ? 9.81f : 0.0f));
  for (std::size_t i = 0; i < 3; ++i) b.x[i] += dt * b.v[i];
  const Vec3 jw{j[0] * b.w[0], j[1] * b.w[1], j[2] * b.w[2]};
  const Vec3 gyro{b.w[1] * jw[2] - b.w[2] * jw[1], b.w[2] * jw[0] - b.w[0] * jw[2],
                  b.w[0] * jw[1] - b.w[1] * jw[0]};
  for (std::size_t i = 0; i < 3; ++i) b.w[i] += dt * (torque[i] - gyro[i]) / j[i];
  // R <- R exp([w dt]x), Rodrigues.
  const float a[3] = {b.w[0] * dt, b.w[1] * dt, b.w[2] * dt};
  const float th = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
  Mat3 e{1.0f, 0.0f, 0.0f, 0.0f, 1.0f, 0.0f, 0.0f, 0.0f, 1.0f};
  if (th > 0.0f) {
    const float k[3] = {a[0] / th, a[1] / th, a[2] / th}, s = std::sin(th), c = 1.0f - std::cos(th);
    const Mat3 kx{0.0f, -k[2], k[1], k[2], 0.0f, -k[0], -k[1], k[0], 0.0f};
    for (std::size_t i = 0; i < 3; ++i)
      for (std::size_t jj = 0; jj < 3; ++jj) {
        float kk = 0.0f;
        for (std::size_t m = 0; m < 3; ++m) kk += kx[3 * i + m] * kx[3 * m + jj];
        e[3 * i + jj] += s * kx[3 * i + jj] + c * kk;
      }
  }
  Mat3 r{};
  for (std::size_t i = 0; i < 3; ++i)
    for (std::size_t jj = 0; jj < 3; ++jj)
      for (std::size_t m = 0; m < 3; ++m) r[3 * i + jj] += b.r[3 * i + m] * e[3 * m + jj];
  b.r = r;
}

TvmdReference tilt_reference(float t) {
  const float roll = t < 1.0f ? 0.0f : t < 3.0f ? 1.04719755f * (t - 1.0f) / 2.0f : 1.04719755f;
  TvmdReference r;
  std::memset(&r, 0, sizeof r);
  r.size = sizeof r;
  r.position[2] = 1.5f;
  const float c = std::cos(roll), s = std::sin(roll);
  const float m[9] = {1.0f, 0.0f, 0.0f, 0.0f, c, -s, 0.0f, s, c};
  std::memcpy(r.attitude, m, sizeof m);
  return r;
}

float planned_roll(const float r_d[9]) { return std::atan2(r_d[7], r_d[8]); }

void test_cascade_flight() {
  TvmdConfig config = paper();
  float mass = config.navigator_mass;
  Vec3 j{0.0f, 0.0f, 0.0f};
  for (std::size_t i = 0; i < config.agent_count; ++i) {
    const float *p = config.agents[i].position, m = config.agents[i].mass;
    mass += m;
    j[0] += m * (p[1] * p[1] + p[2] * p[2]);
    j[1] += m * (p[0] * p[0] + p[2] * p[2]);
    j[2] += m * (p[0] * p[0] + p[1] * p[1]);
  }
  for (float &c : j) c += 0.01f;  // the agents' own inertia, roughly
  CHECK(tvmd_create(&whole_storage, sizeof whole_storage, &config) == TVMD_OK);
  CHECK(tvmd_create(&staged_storage, sizeof staged_storage, &config) == TVMD_OK);
  tvmd::px4::Cascade cascade(&staged_storage);
  Body full, staged;
  TvmdOutput out;
  std::memset(&out, 0, sizeof out);
  out.size = sizeof out;
  TvmdAllocationOutput alloc;
  std::memset(&alloc, 0, sizeof alloc);
  alloc.size = sizeof alloc;
  float max_full = 0.0f, max_staged = 0.0f, held_torque[3] = {0}, held_force[3] = {0};
  float staged_torque[3] = {0}, staged_force[3] = {0};
  for (int k = 0; k < 4000; ++k) {  // 4 s at 1 kHz
    const float t = 0.001f * static_cast<float>(k);
    const TvmdReference ref = tilt_reference(t);
    if (k % 4 == 0) {  // 250 Hz: the full step; the cascade's attitude and allocation
      const TvmdState s = state_of(full);
      CHECK(tvmd_step(&whole_storage, &s, &ref, &out) == TVMD_OK);
      max_full = std::fmax(max_full, planned_roll(out.planned_attitude));
      TvmdLawOutput law;
      std::memset(&law, 0, sizeof law);
      law.size = sizeof law;
      // The full flight's plant gets the law's wrench, which the step's allocation meets
      // (e_f at round-off: A4-Inc holds every wrench of this flight at s = 0.5).
      CHECK(tvmd_law(&whole_storage, &s, &ref, &law) == TVMD_OK);
      CHECK(out.e_f < 1e-3f);
      std::memcpy(held_torque, law.torque, sizeof held_torque);
      std::memcpy(held_force, law.force, sizeof held_force);
      const TvmdState ss = state_of(staged);
      if (k % 20 == 0) {  // 50 Hz: the law stage (position loop)
        CHECK(cascade.position(ss, ref) == TVMD_OK);
        max_staged = std::fmax(max_staged, planned_roll(cascade.law().planned_attitude));
      }
      CHECK(cascade.attitude_and_allocate(ss, &alloc) == TVMD_OK);
      std::memcpy(staged_torque, alloc.allocated_torque, sizeof staged_torque);
      std::memcpy(staged_force, alloc.allocated_force, sizeof staged_force);
    }
    advance(full, held_torque, held_force, mass, j, 0.001f);
    advance(staged, staged_torque, staged_force, mass, j, 0.001f);
  }
  std::printf("max planned roll: full step %.6f rad, cascade %.6f rad\n",
              static_cast<double>(max_full), static_cast<double>(max_staged));
  CHECK(std::fabs(max_full - max_staged) < 1e-3f);
  // The planner saturates well below the infeasible pi/3.
  CHECK(max_full > 0.2f && max_full < 0.5f);
  CHECK(std::fabs(staged.x[2] - 1.5f) < 0.2f);
}


float total_thrust(const TvmdAllocationOutput &a) {
  float t = 0.0f;
  for (std::size_t i = 0; i < a.agent_count; ++i) t += a.commands[i].thrust;
  return t;
}

bool all_finite(const float *v, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(v[i])) return false;
  }
  return true;
}

// The cascade keeps flying through a bad sample: a NaN gyro sample gets the held commands (not
// an unwritten output), a refused law period keeps the last good law output, and every error is
// counted in the report.
void test_cascade_bad_samples() {
  TvmdConfig config = paper();
  CHECK(tvmd_create(&staged_storage, sizeof staged_storage, &config) == TVMD_OK);
  tvmd::px4::Cascade cascade(&staged_storage);
  TvmdAllocationOutput alloc;
  std::memset(&alloc, 0, sizeof alloc);
  alloc.size = sizeof alloc;
  Body body;
  const TvmdReference hover = tilt_reference(0.0f);
  // Before the first law period: the held (idle) commands, written, and the status says why.
  alloc.agent_count = 99;
  CHECK(cascade.attitude_and_allocate(state_of(body), &alloc) == TVMD_ERR_NOT_INITIALIZED);
  CHECK(alloc.status == TVMD_ERR_NOT_INITIALIZED && alloc.agent_count == config.agent_count);
  CHECK(cascade.report().attitude.errors == 1);
  // Hover: the law at 50 Hz, the attitude and the allocation at 250 Hz.
  for (int k = 0; k < 250; ++k) {
    const TvmdState s = state_of(body);
    if (k % 5 == 0) CHECK(cascade.position(s, hover) == TVMD_OK);
    CHECK(cascade.attitude_and_allocate(s, &alloc) == TVMD_OK);
  }
  const TvmdAllocationOutput good = alloc;
  const float weight = 9.81f * (config.navigator_mass + 4.0f * config.agents[0].mass);
  std::printf("hover through the cascade: total thrust %.3f N (weight %.3f N)\n",
              static_cast<double>(total_thrust(good)), static_cast<double>(weight));
  CHECK(std::fabs(total_thrust(good) - weight) < 0.05f * weight);

  // One NaN gyro sample: refused, and the output is the held commands, bit for bit.
  std::memset(alloc.commands, 0, sizeof alloc.commands);
  TvmdState bad = state_of(body);
  bad.angular_velocity[0] = NAN;
  CHECK(cascade.attitude_and_allocate(bad, &alloc) == TVMD_ERR_INPUT_NON_FINITE);
  CHECK(alloc.status == TVMD_ERR_INPUT_NON_FINITE);
  CHECK(std::memcmp(alloc.commands, good.commands, sizeof alloc.commands) == 0);
  CHECK(total_thrust(alloc) > 0.9f * weight);
  CHECK(cascade.report().attitude.last_error == TVMD_ERR_INPUT_NON_FINITE);
  CHECK(cascade.report().attitude.errors == 2 && cascade.report().attitude.consecutive == 1);
  // The next good sample flies again.
  CHECK(cascade.attitude_and_allocate(state_of(body), &alloc) == TVMD_OK);
  CHECK(cascade.report().attitude.consecutive == 0);

  // One refused law period (a NaN position): the last good law output stays, the fast loop
  // keeps allocating from it.
  const TvmdLawOutput kept = cascade.law();
  bad = state_of(body);
  bad.position[2] = NAN;
  CHECK(cascade.position(bad, hover) == TVMD_ERR_INPUT_NON_FINITE);
  CHECK(std::memcmp(&cascade.law(), &kept, sizeof kept) == 0);
  CHECK(all_finite(cascade.law().planned_attitude, 9) && all_finite(cascade.law().force, 3));
  CHECK(cascade.report().law.errors == 1 && cascade.report().law.consecutive == 1);
  for (int k = 0; k < 5; ++k) {
    CHECK(cascade.attitude_and_allocate(state_of(body), &alloc) == TVMD_OK);
    CHECK(total_thrust(alloc) > 0.9f * weight);
  }
  CHECK(cascade.position(state_of(body), hover) == TVMD_OK);
  CHECK(cascade.report().law.consecutive == 0 && cascade.report().law.errors == 1);
  CHECK(cascade.report().allocate.errors == 0);
}

// The offset-free compensation through the cascade (tvmd_compensation after each allocation):
// NaN before the first allocation, then, in a hover under a constant unmodelled force d with
// the default (offset-free) law, the observer's estimate -compensation converges to d.
void test_cascade_compensation() {
  TvmdConfig config;
  std::memset(&config, 0, sizeof config);
  config.size = sizeof config;
  CHECK(tvmd_config_default(&config) == TVMD_OK);
  CHECK(tvmd_create(&staged_storage, sizeof staged_storage, &config) == TVMD_OK);
  tvmd::px4::Cascade cascade(&staged_storage);
  CHECK(std::isnan(cascade.compensation().force[0]) && std::isnan(cascade.compensation().torque[2]));
  float mass = config.navigator_mass;
  for (std::size_t i = 0; i < config.agent_count; ++i) mass += config.agents[i].mass;
  const Vec3 j{0.2f, 0.2f, 0.4f};
  const float d[3] = {0.5f, -0.3f, -1.0f};  // N, world frame
  const TvmdReference hover = tilt_reference(0.0f);
  TvmdAllocationOutput alloc;
  std::memset(&alloc, 0, sizeof alloc);
  alloc.size = sizeof alloc;
  Body body;
  float torque[3] = {0}, force[3] = {0};
  const int law_every = static_cast<int>(std::lround(config.period / 0.002f));
  for (int k = 0; k < 5000; ++k) {  // 10 s at 500 Hz; the law at the configuration's period
    const TvmdState s = state_of(body);
    if (k % law_every == 0) CHECK(cascade.position(s, hover) == TVMD_OK);
    CHECK(cascade.attitude_and_allocate(s, &alloc) == TVMD_OK);
    std::memcpy(torque, alloc.allocated_torque, sizeof torque);
    std::memcpy(force, alloc.allocated_force, sizeof force);
    for (int sub = 0; sub < 2; ++sub) {
      advance(body, torque, force, mass, j, 0.001f);
      for (std::size_t i = 0; i < 3; ++i) body.v[i] += 0.001f * d[i] / mass;
    }
  }
  const TvmdCompensation &c = cascade.compensation();
  std::printf("compensation through the cascade: (%.3f, %.3f, %.3f) N for d = (%.1f, %.1f, %.1f) N\n",
              static_cast<double>(c.force[0]), static_cast<double>(c.force[1]),
              static_cast<double>(c.force[2]), static_cast<double>(d[0]), static_cast<double>(d[1]),
              static_cast<double>(d[2]));
  for (std::size_t i = 0; i < 3; ++i) CHECK(near(c.force[i], -d[i], 0.05f));
  CHECK(all_finite(c.torque, 3));
  CHECK(cascade.report().compensation.errors == 0 && cascade.report().allocate.errors == 0);
  CHECK(std::fabs(body.x[2] - 1.5f) < 0.01f);
  // Landed: zero at the next allocation.
  CHECK(tvmd_set_landed(&staged_storage, 1) == TVMD_OK);
  CHECK(cascade.attitude_and_allocate(state_of(body), &alloc) == TVMD_OK);
  CHECK(cascade.compensation().force[0] == 0.0f && cascade.compensation().force[2] == 0.0f);
}
}  // namespace

int main() {
  test_frames();
  test_hover_matches_c();
  test_cascade_flight();
  test_cascade_bad_samples();
  test_cascade_compensation();
  std::printf("tvmd C++ PX4 adapter test: %d checks, %d failed\n", checks, failed);
  return failed == 0 ? 0 : 1;
}
