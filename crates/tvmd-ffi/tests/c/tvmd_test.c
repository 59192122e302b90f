/* The C test of the tvmd C interface (run by scripts/ffi.sh).
 *
 * Links libtvmd_ffi.a and runs the paper team through hover, the tilt (the planner
 * saturating), failure masks, reset and every error path, then the offset-free law (law_test.c),
 * checking what C can check alone (statuses, held commands, channel placement, round trips).
 * Every call that reaches the core is also written, inputs and outputs as float bits, to the
 * record file given as argv[1]: the Rust test crates/tvmd-ffi/tests/c_record.rs replays it on
 * the Rust API and compares exactly.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "check.h"

int checks = 0, failed = 0;
FILE *record = NULL;

static uint32_t bits(float x) {
  uint32_t u;
  memcpy(&u, &x, sizeof u);
  return u;
}

static void put_floats(const float *x, size_t n) {
  size_t i;
  for (i = 0; i < n; ++i) fprintf(record, " %08lx", (unsigned long)bits(x[i]));
}

void identity(float m[9]) {
  memset(m, 0, 9 * sizeof m[0]);
  m[0] = m[4] = m[8] = 1.0f;
}

static void roll(float m[9], float phi) {
  identity(m);
  m[4] = cosf(phi);
  m[5] = -sinf(phi);
  m[7] = sinf(phi);
  m[8] = cosf(phi);
}

TvmdState at_rest(float x, float y, float z) {
  TvmdState s;
  memset(&s, 0, sizeof s);
  s.size = sizeof s;
  s.position[0] = x;
  s.position[1] = y;
  s.position[2] = z;
  identity(s.attitude);
  return s;
}

TvmdReference hover_at(float x, float y, float z) {
  TvmdReference r;
  memset(&r, 0, sizeof r);
  r.size = sizeof r;
  r.position[0] = x;
  r.position[1] = y;
  r.position[2] = z;
  identity(r.attitude);
  return r;
}

TvmdOutput empty_output(void) {
  TvmdOutput o;
  memset(&o, 0, sizeof o);
  o.size = sizeof o;
  return o;
}

/* One recorded step: "step STATUS state(18) reference(24) commands(64) e_f R_d(9) theta
 * compensation(6) planner_status iterations". */
TvmdStatus step(TvmdController *c, const TvmdState *s, const TvmdReference *r,
                       TvmdOutput *o) {
  TvmdStatus status = tvmd_step(c, s, r, o);
  size_t i;
  CHECK(o->status == status);
  fprintf(record, "step %d", (int)status);
  put_floats(s->position, 3);
  put_floats(s->attitude, 9);
  put_floats(s->angular_velocity, 3);
  put_floats(s->velocity, 3);
  put_floats(r->position, 3);
  put_floats(r->velocity, 3);
  put_floats(r->acceleration, 3);
  put_floats(r->attitude, 9);
  put_floats(r->angular_velocity, 3);
  put_floats(r->angular_acceleration, 3);
  for (i = 0; i < TVMD_MAX_AGENTS; ++i) {
    const float c4[4] = {o->commands[i].eta_x, o->commands[i].eta_y, o->commands[i].thrust,
                         o->commands[i].omega};
    put_floats(c4, 4);
  }
  put_floats(&o->e_f, 1);
  put_floats(o->planned_attitude, 9);
  put_floats(&o->planner_theta, 1);
  put_floats(o->compensation_force, 3);
  put_floats(o->compensation_torque, 3);
  fprintf(record, " %u %u\n", (unsigned)o->planner_status, (unsigned)o->planner_iterations);
  return status;
}

/* "failures MASK STATUS capable margin limiting_agent limit weight". */
static TvmdStatus set_failures(TvmdController *c, uint32_t mask, TvmdHover *h) {
  TvmdStatus status;
  memset(h, 0, sizeof *h);
  h->size = sizeof *h;
  status = tvmd_set_failures(c, mask, h);
  fprintf(record, "failures %lx %d %u", (unsigned long)mask, (int)status, (unsigned)h->capable);
  put_floats(&h->margin, 1);
  fprintf(record, " %d %u", (int)h->limiting_agent, (unsigned)h->limit);
  put_floats(&h->weight, 1);
  fprintf(record, "\n");
  return status;
}

static int same_commands(const TvmdOutput *a, const TvmdOutput *b) {
  return memcmp(a->commands, b->commands, sizeof a->commands) == 0;
}

int diagnostics_nan(const TvmdOutput *o) {
  return isnan(o->e_f) && isnan(o->planner_theta) && isnan(o->planned_attitude[0]) &&
         isnan(o->compensation_force[0]) && isnan(o->compensation_torque[2]);
}

static TvmdConfig paper_config(void) {
  TvmdConfig config;
  memset(&config, 0, sizeof config);
  config.size = sizeof config;
  CHECK_STATUS(tvmd_config_paper(&config), TVMD_OK);
  return config;
}

static TvmdController storage; /* static: zero-initialized, so "not initialized" */

static void test_create_errors(void) {
  TvmdConfig config = paper_config();
  TvmdConfig bad;
  TvmdState s = at_rest(0.0f, 0.0f, 1.5f);
  TvmdReference r = hover_at(0.0f, 0.0f, 1.5f);
  TvmdOutput o = empty_output();
  static uint64_t raw[TVMD_CONTROLLER_WORDS + 1];
  size_t i;

  /* A handle never created: refused, idle commands held. */
  CHECK_STATUS(tvmd_step(&storage, &s, &r, &o), TVMD_ERR_NOT_INITIALIZED);
  CHECK(o.commands[0].thrust == 0.0f && diagnostics_nan(&o));
  CHECK_STATUS(tvmd_reset(&storage), TVMD_ERR_NOT_INITIALIZED);
  CHECK_STATUS(tvmd_reset(NULL), TVMD_ERR_NULL_POINTER);

  CHECK_STATUS(tvmd_create(NULL, sizeof storage, &config), TVMD_ERR_NULL_POINTER);
  CHECK_STATUS(tvmd_create(&storage, sizeof storage, NULL), TVMD_ERR_NULL_POINTER);
  CHECK_STATUS(tvmd_create(&storage, sizeof storage - 8, &config), TVMD_ERR_SIZE);
  CHECK_STATUS(tvmd_create((TvmdController *)(void *)((char *)raw + 4), sizeof storage, &config),
               TVMD_ERR_ALIGNMENT);
  CHECK_STATUS(tvmd_config_paper(NULL), TVMD_ERR_NULL_POINTER);
  bad = config;
  bad.size = 4;
  CHECK_STATUS(tvmd_config_paper(&bad), TVMD_ERR_SIZE);
  CHECK_STATUS(tvmd_create(&storage, sizeof storage, &bad), TVMD_ERR_SIZE);

  bad = config; bad.agent_count = 0;
  CHECK_STATUS(tvmd_create(&storage, sizeof storage, &bad), TVMD_ERR_CONFIG_NO_AGENTS);
  bad = config; bad.agent_count = TVMD_MAX_AGENTS + 1;
  CHECK_STATUS(tvmd_create(&storage, sizeof storage, &bad), TVMD_ERR_CONFIG_TOO_MANY_AGENTS);
  bad = config; bad.agents[1].mass = NAN;
  CHECK_STATUS(tvmd_create(&storage, sizeof storage, &bad), TVMD_ERR_CONFIG_NON_FINITE);
  bad = config; bad.agents[1].position[0] = INFINITY;
  CHECK_STATUS(tvmd_create(&storage, sizeof storage, &bad), TVMD_ERR_CONFIG_NON_FINITE);
  bad = config; bad.agents[2].mass = -1.0f;
  CHECK_STATUS(tvmd_create(&storage, sizeof storage, &bad), TVMD_ERR_CONFIG_MASS);
  bad = config; bad.limits.sigma_x = 2.0f;
  CHECK_STATUS(tvmd_create(&storage, sizeof storage, &bad), TVMD_ERR_CONFIG_GIMBAL_LIMIT);
  bad = config; bad.limits.max_thrust = 0.0f;
  CHECK_STATUS(tvmd_create(&storage, sizeof storage, &bad), TVMD_ERR_CONFIG_THRUST);
  bad = config; bad.limits.min_thrust = bad.limits.max_thrust;
  CHECK_STATUS(tvmd_create(&storage, sizeof storage, &bad), TVMD_ERR_CONFIG_IDLE_THRUST);
  bad = config; bad.limits.rotor_model = 9;
  CHECK_STATUS(tvmd_create(&storage, sizeof storage, &bad), TVMD_ERR_ENUM_VALUE);
  bad = config; bad.navigator_inertia[0] = -1.0f;
  CHECK_STATUS(tvmd_create(&storage, sizeof storage, &bad), TVMD_ERR_CONFIG_NAVIGATOR_INERTIA);
  bad = config; bad.agents[0].inertia[8] = -1.0f;
  CHECK_STATUS(tvmd_create(&storage, sizeof storage, &bad), TVMD_ERR_CONFIG_AGENT_INERTIA);
  bad = config; bad.gains.k_x[1] = 5.0f; /* not symmetric */
  CHECK_STATUS(tvmd_create(&storage, sizeof storage, &bad), TVMD_ERR_CONFIG_NOT_SPD);
  bad = config; bad.agents[0].mass = 3e38f;
  CHECK_STATUS(tvmd_create(&storage, sizeof storage, &bad), TVMD_ERR_CONFIG_OVERFLOW);
  bad = config; bad.agent_count = 2; /* two agents on a line */
  bad.agents[1] = bad.agents[2];
  CHECK_STATUS(tvmd_create(&storage, sizeof storage, &bad), TVMD_ERR_CONFIG_RANK_DEFICIENT);
  bad = config; bad.relaxation = 0.0f;
  CHECK_STATUS(tvmd_create(&storage, sizeof storage, &bad), TVMD_ERR_CONFIG_RELAXATION);
  bad = config; bad.period = 0.0f;
  CHECK_STATUS(tvmd_create(&storage, sizeof storage, &bad), TVMD_ERR_CONFIG_PARAMETER);
  bad = config; bad.rate_limited = 1; bad.rate_limits[1] = -1.0f;
  CHECK_STATUS(tvmd_create(&storage, sizeof storage, &bad), TVMD_ERR_CONFIG_PARAMETER);
  bad = config; bad.allocator = TVMD_ALLOCATOR_WEIGHTED_PSEUDO_INVERSE; bad.agent_weights[3] = 0.0f;
  CHECK_STATUS(tvmd_create(&storage, sizeof storage, &bad), TVMD_ERR_CONFIG_PARAMETER);
  bad = config; bad.allocator = 7;
  CHECK_STATUS(tvmd_create(&storage, sizeof storage, &bad), TVMD_ERR_CONFIG_UNKNOWN_ALLOCATOR);

  /* A failed create leaves the handle not initialized. */
  CHECK_STATUS(tvmd_step(&storage, &s, &r, &o), TVMD_ERR_NOT_INITIALIZED);

  /* The other allocators and rotor constants create. */
  bad = config; bad.allocator = TVMD_ALLOCATOR_WEIGHTED_PSEUDO_INVERSE;
  for (i = 0; i < TVMD_MAX_AGENTS; ++i) bad.agent_weights[i] = 0.0f; /* unused slots ignored */
  for (i = 0; i < bad.agent_count; ++i) bad.agent_weights[i] = 1.0f + (float)i;
  CHECK_STATUS(tvmd_create(&storage, sizeof storage, &bad), TVMD_OK);
  bad = config; bad.allocator = TVMD_ALLOCATOR_REDISTRIBUTED_PSEUDO_INVERSE; /* the paper's */
  CHECK_STATUS(tvmd_create(&storage, sizeof storage, &bad), TVMD_OK);
  bad = config; bad.allocator = TVMD_ALLOCATOR_PSEUDO_INVERSE;
  bad.limits.rotor_model = TVMD_ROTOR_CONSTANTS;
  bad.limits.rho = 1.225f; bad.limits.rotor_diameter = 0.254f;
  bad.limits.lift_coefficient = 0.11f; bad.limits.max_rotor_speed = 900.0f;
  CHECK_STATUS(tvmd_create(&storage, sizeof storage, &bad), TVMD_OK);

  /* The round cap is the exact-boundary redistribution's and the capped redistribution's
   * alone. Capped, a step is as good as the cap allows: never a smaller e_f than the uncapped
   * walk's. */
  bad = config; bad.allocator = TVMD_ALLOCATOR_REDISTRIBUTED_PSEUDO_INVERSE;
  bad.allocator_round_cap = TVMD_ROUND_CAP_ROUNDS;
  bad.allocator_max_rounds = 2;
  CHECK_STATUS(tvmd_create(&storage, sizeof storage, &bad), TVMD_ERR_CONFIG_UNUSED_OPTION);
  /* No cap promises no bound: every allocator takes it, and the default. */
  bad.allocator_round_cap = TVMD_ROUND_CAP_UNCAPPED;
  CHECK_STATUS(tvmd_create(&storage, sizeof storage, &bad), TVMD_OK);
  bad.allocator_round_cap = TVMD_ROUND_CAP_DEFAULT;
  CHECK_STATUS(tvmd_create(&storage, sizeof storage, &bad), TVMD_OK);
  bad = config; bad.allocator_round_cap = 3;
  CHECK_STATUS(tvmd_create(&storage, sizeof storage, &bad), TVMD_ERR_ENUM_VALUE);
  {
    TvmdController uncapped;
    TvmdOutput capped_out = o, uncapped_out = o;
    bad = config; bad.allocator = TVMD_ALLOCATOR_EXACT_BOUNDARY_REDISTRIBUTION;
    bad.allocator_round_cap = TVMD_ROUND_CAP_UNCAPPED;
    CHECK_STATUS(tvmd_create(&uncapped, sizeof uncapped, &bad), TVMD_OK);
    /* Every cap, the start alone (0 rounds) included, is a bound the walk respects. */
    bad.allocator_round_cap = TVMD_ROUND_CAP_ROUNDS;
    bad.allocator_max_rounds = 0;
    CHECK_STATUS(tvmd_create(&storage, sizeof storage, &bad), TVMD_OK);
    CHECK_STATUS(tvmd_step(&storage, &s, &r, &capped_out), TVMD_OK);
    CHECK_STATUS(tvmd_step(&uncapped, &s, &r, &uncapped_out), TVMD_OK);
    CHECK(capped_out.e_f >= uncapped_out.e_f - 1e-5f);
    bad.allocator_max_rounds = 1;
    CHECK_STATUS(tvmd_create(&storage, sizeof storage, &bad), TVMD_OK);
    CHECK_STATUS(tvmd_step(&storage, &s, &r, &capped_out), TVMD_OK);
    CHECK_STATUS(tvmd_step(&uncapped, &s, &r, &uncapped_out), TVMD_OK);
    CHECK(capped_out.e_f >= uncapped_out.e_f - 1e-5f);
    /* The capped redistribution takes its rounds the same way, at least one. */
    bad.allocator = TVMD_ALLOCATOR_CAPPED_REDISTRIBUTION;
    CHECK_STATUS(tvmd_create(&storage, sizeof storage, &bad), TVMD_OK);
    CHECK_STATUS(tvmd_step(&storage, &s, &r, &capped_out), TVMD_OK);
    CHECK(capped_out.e_f >= uncapped_out.e_f - 1e-5f);
    bad.allocator_max_rounds = 0;
    CHECK_STATUS(tvmd_create(&storage, sizeof storage, &bad), TVMD_ERR_CONFIG_PARAMETER);
  }
}

static void test_actuators(TvmdController *c, const TvmdOutput *o, uint32_t failed_mask) {
  TvmdActuatorMap map, bad;
  TvmdActuatorOutputs act, round;
  TvmdAgentCommand back[TVMD_MAX_AGENTS];
  const float sigma_x = 3.14159265f / 6.0f, sigma_y = 3.14159265f / 4.0f;
  size_t i, k;

  memset(&map, 0, sizeof map);
  map.size = sizeof map;
  memset(&act, 0, sizeof act);
  act.size = sizeof act;
  CHECK_STATUS(tvmd_actuator_map_default(c, &map), TVMD_OK);
  CHECK_STATUS(tvmd_actuator_map_validate(c, &map), TVMD_OK);
  CHECK_STATUS(tvmd_actuator_outputs(c, &map, o->commands, TVMD_MAX_AGENTS, &act), TVMD_OK);
  for (i = 0; i < 4; ++i) {
    int dead = (failed_mask >> i) & 1u;
    float m = act.motors[2 * i];
    if (dead) {
      /* Stopped (PX4's NaN), the gimbal at trim. */
      CHECK(isnan(m) && isnan(act.motors[2 * i + 1]));
      CHECK(act.servos[2 * i] == 0.0f && act.servos[2 * i + 1] == 0.0f);
    } else {
      CHECK(m == act.motors[2 * i + 1]); /* eq. 5: both rotors of the pair at one speed */
      CHECK(m >= 0.0f && m <= 1.0f);
      /* Normalized rotor speed: omega is normalized to 1 at max thrust in the paper config. */
      CHECK(fabsf(m - o->commands[i].omega) <= 1e-6f);
      CHECK(fabsf(act.servos[2 * i] - o->commands[i].eta_x / sigma_x) <= 1e-6f);
      CHECK(fabsf(act.servos[2 * i + 1] - o->commands[i].eta_y / sigma_y) <= 1e-6f);
    }
  }
  for (i = 8; i < TVMD_MAX_AGENTS; ++i) CHECK(isnan(act.motors[i]) && isnan(act.servos[i]));

  /* A scrambled map with trims, reversed servos and reduced deflection. */
  for (i = 0; i < 4; ++i) {
    map.agents[i].motor[0] = (uint32_t)(11 - 2 * i);
    map.agents[i].motor[1] = (uint32_t)(2 * i);
    map.agents[i].servo[0] = (uint32_t)(7 - i);
    map.agents[i].servo[1] = (uint32_t)i;
    map.agents[i].servo_trim[0] = 0.1f;
    map.agents[i].servo_trim[1] = -0.05f;
    map.agents[i].servo_direction[0] = -1.0f;
    map.agents[i].servo_direction[1] = (i % 2) ? -1.0f : 1.0f;
    map.agents[i].servo_range[0] = sigma_x / 0.8f;
    map.agents[i].servo_range[1] = sigma_y / 0.9f;
  }
  for (k = 0; k < 2; ++k) {
    map.motor_curve = k ? TVMD_MOTOR_CURVE_THRUST : TVMD_MOTOR_CURVE_ROTOR_SPEED;
    CHECK_STATUS(tvmd_actuator_outputs(c, &map, o->commands, TVMD_MAX_AGENTS, &act), TVMD_OK);
    for (i = 0; i < 4; ++i) {
      const TvmdAgentChannels *a = &map.agents[i];
      int dead = (failed_mask >> i) & 1u;
      float motor = k ? o->commands[i].thrust / (2.0f * 0.7f * 9.81f) : o->commands[i].omega;
      if (dead) {
        CHECK(isnan(act.motors[a->motor[0]]) && isnan(act.motors[a->motor[1]]));
        CHECK(act.servos[a->servo[0]] == a->servo_trim[0]);
        CHECK(act.servos[a->servo[1]] == a->servo_trim[1]);
      } else {
        CHECK(act.motors[a->motor[0]] == act.motors[a->motor[1]]);
        CHECK(fabsf(act.motors[a->motor[0]] - motor) <= 1e-6f);
        CHECK(fabsf(act.servos[a->servo[0]] - (0.1f - 0.8f * o->commands[i].eta_x / sigma_x)) <= 1e-6f);
        CHECK(fabsf(act.servos[a->servo[1]] -
                    (-0.05f + a->servo_direction[1] * 0.9f * o->commands[i].eta_y / sigma_y)) <= 1e-6f);
      }
    }
    /* Channels no agent uses: motors 1, 3, 8, 10, 12..15; servos 1, 3, 5, 7..11. */
    CHECK(isnan(act.motors[1]) && isnan(act.motors[8]) && isnan(act.motors[12]) && isnan(act.servos[8]) && isnan(act.servos[10]));
    /* The round trip: outputs -> commands -> outputs. */
    CHECK_STATUS(tvmd_actuator_commands(c, &map, &act, back, TVMD_MAX_AGENTS), TVMD_OK);
    for (i = 0; i < 4; ++i) {
      int dead = (failed_mask >> i) & 1u;
      const TvmdAgentCommand *want = &o->commands[i];
      CHECK(fabsf(back[i].eta_x - (dead ? 0.0f : want->eta_x)) <= 1e-5f);
      CHECK(fabsf(back[i].eta_y - (dead ? 0.0f : want->eta_y)) <= 1e-5f);
      CHECK(fabsf(back[i].thrust - (dead ? 0.0f : want->thrust)) <= 1e-4f);
      CHECK(fabsf(back[i].omega - (dead ? 0.0f : want->omega)) <= 1e-5f);
    }
    round = act;
    CHECK_STATUS(tvmd_actuator_outputs(c, &map, back, TVMD_MAX_AGENTS, &round), TVMD_OK);
    for (i = 0; i < TVMD_MAX_AGENTS; ++i) {
      CHECK((isnan(act.motors[i]) && isnan(round.motors[i])) || fabsf(act.motors[i] - round.motors[i]) <= 1e-6f);
      CHECK((isnan(act.servos[i]) && isnan(round.servos[i])) || fabsf(act.servos[i] - round.servos[i]) <= 1e-6f);
    }
  }

  /* Map and value errors; outputs are not written on an error. */
  round = act;
  bad = map; bad.agents[2].motor[1] = TVMD_MAX_AGENTS;
  CHECK_STATUS(tvmd_actuator_map_validate(c, &bad), TVMD_ERR_MAP_CHANNEL_RANGE);
  /* PX4's actuator_motors has 12 channels and actuator_servos 8. */
  bad = map; bad.agents[1].motor[0] = TVMD_MOTOR_CHANNELS;
  CHECK_STATUS(tvmd_actuator_map_validate(c, &bad), TVMD_ERR_MAP_CHANNEL_RANGE);
  bad = map; bad.agents[0].servo[1] = TVMD_SERVO_CHANNELS;
  CHECK_STATUS(tvmd_actuator_map_validate(c, &bad), TVMD_ERR_MAP_CHANNEL_RANGE);
  CHECK_STATUS(tvmd_actuator_outputs(c, &bad, o->commands, TVMD_MAX_AGENTS, &round), TVMD_ERR_MAP_CHANNEL_RANGE);
  CHECK(memcmp(&round, &act, sizeof act) == 0);
  bad = map; bad.agents[3].servo[0] = bad.agents[0].servo[1];
  CHECK_STATUS(tvmd_actuator_map_validate(c, &bad), TVMD_ERR_MAP_DUPLICATE_CHANNEL);
  bad = map; bad.agents[3].motor[1] = bad.agents[3].motor[0];
  CHECK_STATUS(tvmd_actuator_map_validate(c, &bad), TVMD_ERR_MAP_DUPLICATE_CHANNEL);
  bad = map; bad.agents[1].servo_trim[0] = 0.3f; /* 0.3 + 0.8 > 1 */
  CHECK_STATUS(tvmd_actuator_map_validate(c, &bad), TVMD_ERR_MAP_SERVO);
  bad = map; bad.agents[1].servo_direction[1] = 0.0f;
  CHECK_STATUS(tvmd_actuator_map_validate(c, &bad), TVMD_ERR_MAP_SERVO);
  bad = map; bad.agents[1].servo_range[1] = NAN;
  CHECK_STATUS(tvmd_actuator_map_validate(c, &bad), TVMD_ERR_MAP_SERVO);
  bad = map; bad.agent_count = 3;
  CHECK_STATUS(tvmd_actuator_map_validate(c, &bad), TVMD_ERR_MAP_AGENT_COUNT);
  bad = map; bad.motor_curve = 5;
  CHECK_STATUS(tvmd_actuator_map_validate(c, &bad), TVMD_ERR_ENUM_VALUE);
  bad = map; bad.size = 0;
  CHECK_STATUS(tvmd_actuator_map_validate(c, &bad), TVMD_ERR_SIZE);
  CHECK_STATUS(tvmd_actuator_map_validate(c, NULL), TVMD_ERR_NULL_POINTER);
  CHECK_STATUS(tvmd_actuator_map_validate(NULL, &map), TVMD_ERR_NULL_POINTER);
  CHECK_STATUS(tvmd_actuator_outputs(c, &map, NULL, TVMD_MAX_AGENTS, &round), TVMD_ERR_NULL_POINTER);
  CHECK_STATUS(tvmd_actuator_outputs(c, &map, o->commands, 3, &round), TVMD_ERR_SIZE);
  CHECK_STATUS(tvmd_actuator_outputs(c, &map, o->commands, TVMD_MAX_AGENTS, NULL), TVMD_ERR_NULL_POINTER);
  round.size = 0;
  CHECK_STATUS(tvmd_actuator_outputs(c, &map, o->commands, TVMD_MAX_AGENTS, &round), TVMD_ERR_SIZE);
  round.size = sizeof round;
  memcpy(back, o->commands, sizeof back);
  back[3].eta_y = NAN; /* agent 3 works in every mask of this test */
  CHECK_STATUS(tvmd_actuator_outputs(c, &map, back, TVMD_MAX_AGENTS, &round), TVMD_ERR_ACTUATOR_VALUE);
  memcpy(back, o->commands, sizeof back);
  back[3].eta_x = 1.1f * sigma_x; /* outside E_f: refused, not clipped */
  CHECK_STATUS(tvmd_actuator_outputs(c, &map, back, TVMD_MAX_AGENTS, &round), TVMD_ERR_ACTUATOR_VALUE);
  memcpy(back, o->commands, sizeof back);
  back[3].thrust = 100.0f;
  CHECK_STATUS(tvmd_actuator_outputs(c, &map, back, TVMD_MAX_AGENTS, &round), TVMD_ERR_ACTUATOR_VALUE);
  CHECK(memcmp(&round, &act, sizeof act) == 0);
  memcpy(back, o->commands, sizeof back);
  back[TVMD_MAX_AGENTS - 1].thrust = NAN; /* beyond the team: not read */
  CHECK_STATUS(tvmd_actuator_outputs(c, &map, back, TVMD_MAX_AGENTS, &round), TVMD_OK);
  round = act;
  for (i = 0; i < 4 && ((failed_mask >> i) & 1u); ++i) {
  }
  round.motors[map.agents[i].motor[1]] = round.motors[map.agents[i].motor[0]] * 0.5f + 0.01f;
  CHECK_STATUS(tvmd_actuator_commands(c, &map, &round, back, TVMD_MAX_AGENTS), TVMD_ERR_ACTUATOR_VALUE);
  round = act;
  round.servos[map.agents[i].servo[0]] = NAN;
  CHECK_STATUS(tvmd_actuator_commands(c, &map, &round, back, TVMD_MAX_AGENTS), TVMD_ERR_ACTUATOR_VALUE);
  round = act;
  round.servos[map.agents[i].servo[1]] = 1.5f;
  CHECK_STATUS(tvmd_actuator_commands(c, &map, &round, back, TVMD_MAX_AGENTS), TVMD_ERR_ACTUATOR_VALUE);
}

int main(int argc, char **argv) {
  TvmdConfig config;
  TvmdController *c = &storage;
  TvmdState s;
  TvmdReference r;
  TvmdOutput o = empty_output(), good, held = empty_output();
  TvmdHover hover;
  int i;

  if (argc != 2) {
    fprintf(stderr, "usage: %s RECORD_FILE\n", argv[0]);
    return 2;
  }
  record = fopen(argv[1], "w");
  if (!record) {
    perror(argv[1]);
    return 2;
  }
  CHECK(tvmd_abi_version() == TVMD_ABI_VERSION);
  CHECK(tvmd_controller_size() == sizeof(TvmdController));
  CHECK(sizeof(TvmdController) == TVMD_CONTROLLER_SIZE);
  CHECK(tvmd_controller_align() <= 8 && ((uintptr_t)&storage % tvmd_controller_align()) == 0);
  CHECK(strlen(tvmd_version()) > 0);
  CHECK(strcmp(tvmd_status_name(TVMD_ERR_SIZE), "TVMD_ERR_SIZE") == 0);
  CHECK(strcmp(tvmd_status_name(-77), "TVMD_UNKNOWN_STATUS") == 0);

  test_create_errors();
  config = paper_config();
  CHECK_STATUS(tvmd_create(c, sizeof storage, &config), TVMD_OK);
  memset(&hover, 0, sizeof hover);
  hover.size = sizeof hover;
  CHECK_STATUS(tvmd_hover_capability(c, &hover), TVMD_OK);
  CHECK(hover.capable);
  fprintf(record, "create\n");

  /* Hover, from small offsets. */
  for (i = 0; i < 5; ++i) {
    s = at_rest(0.05f * (float)i, -0.02f * (float)i, 1.5f - 0.01f * (float)i);
    s.velocity[2] = 0.1f * (float)i;
    s.angular_velocity[0] = 0.01f * (float)i;
    r = hover_at(0.0f, 0.0f, 1.5f);
    CHECK_STATUS(step(c, &s, &r, &o), TVMD_OK);
    CHECK(o.agent_count == 4);
    CHECK(o.commands[0].thrust > 0.0f && o.commands[4].thrust == 0.0f);
  }
  CHECK(o.planner_status == TVMD_PLANNER_ALREADY_FEASIBLE);

  /* The tilt: a 1 rad roll reference the team cannot hold; the planner saturates. */
  for (i = 0; i < 5; ++i) {
    s = at_rest(0.2f, 0.0f, 1.5f);
    roll(s.attitude, 0.1f * (float)i);
    r = hover_at(0.0f, 0.0f, 1.5f);
    roll(r.attitude, 1.0f);
    CHECK_STATUS(step(c, &s, &r, &o), TVMD_OK);
    CHECK(o.planner_status == TVMD_PLANNER_PLANNED);
    CHECK(o.planner_theta > 0.0f && o.planner_theta < 1.0f);
  }
  good = o;

  /* Input errors: the previous commands hold, diagnostics NaN. */
  s.position[1] = NAN;
  CHECK_STATUS(step(c, &s, &r, &o), TVMD_ERR_INPUT_NON_FINITE);
  CHECK(same_commands(&o, &good) && diagnostics_nan(&o));
  s = at_rest(0.2f, 0.0f, 1.5f);
  r.angular_acceleration[2] = INFINITY;
  CHECK_STATUS(step(c, &s, &r, &o), TVMD_ERR_INPUT_NON_FINITE);
  CHECK(same_commands(&o, &good));
  r = hover_at(0.0f, 0.0f, 1.5f);
  s.attitude[0] = 2.0f;
  CHECK_STATUS(step(c, &s, &r, &o), TVMD_ERR_INPUT_NOT_ROTATION);
  CHECK(same_commands(&o, &good));
  s = at_rest(1e30f, 0.0f, 1.5f);
  CHECK_STATUS(step(c, &s, &r, &o), TVMD_ERR_INPUT_OUT_OF_RANGE);
  CHECK(same_commands(&o, &good));
  /* Far above the reference with no torque: the only answer is zero thrust, refused. */
  s = at_rest(0.0f, 0.0f, 1000.0f);
  CHECK_STATUS(step(c, &s, &r, &o), TVMD_ERR_INPUT_UNATTAINABLE);
  CHECK(same_commands(&o, &good));

  /* Pointer and size errors (not recorded: they never reach the core). */
  s = at_rest(0.0f, 0.0f, 1.5f);
  CHECK_STATUS(tvmd_step(c, NULL, &r, &held), TVMD_ERR_NULL_POINTER);
  CHECK(same_commands(&held, &good) && held.status == TVMD_ERR_NULL_POINTER);
  CHECK_STATUS(tvmd_step(c, &s, NULL, &held), TVMD_ERR_NULL_POINTER);
  CHECK(same_commands(&held, &good));
  CHECK_STATUS(tvmd_step(c, &s, &r, NULL), TVMD_ERR_NULL_POINTER);
  CHECK_STATUS(tvmd_step(NULL, &s, &r, &held), TVMD_ERR_NULL_POINTER);
  s.size = 8;
  CHECK_STATUS(tvmd_step(c, &s, &r, &held), TVMD_ERR_SIZE);
  CHECK(same_commands(&held, &good) && diagnostics_nan(&held));
  s.size = sizeof s;
  r.size = sizeof r + 4;
  CHECK_STATUS(tvmd_step(c, &s, &r, &held), TVMD_ERR_SIZE);
  r.size = sizeof r;
  held.size = 12;
  held.status = 1234;
  CHECK_STATUS(tvmd_step(c, &s, &r, &held), TVMD_ERR_SIZE);
  CHECK(held.status == 1234); /* a wrongly sized output is not written */
  held.size = sizeof held;
  hover.size = 3;
  CHECK_STATUS(tvmd_set_failures(c, 0, &hover), TVMD_ERR_SIZE);
  CHECK_STATUS(tvmd_hover_capability(c, &hover), TVMD_ERR_SIZE);
  CHECK_STATUS(tvmd_hover_capability(c, NULL), TVMD_ERR_NULL_POINTER);
  CHECK_STATUS(tvmd_set_failures(NULL, 0, NULL), TVMD_ERR_NULL_POINTER);

  test_actuators(c, &good, 0);

  /* Failure masks. Agent 2 lost: rank 6 kept, but hover without margin. */
  CHECK_STATUS(set_failures(c, 1u << 2, &hover), TVMD_OK);
  CHECK(!hover.capable);
  CHECK_STATUS(set_failures(c, 1u << 5, &hover), TVMD_ERR_CONFIG_FAILURE_INDEX);
  CHECK_STATUS(set_failures(c, 1u << 20, &hover), TVMD_ERR_CONFIG_FAILURE_INDEX);
  CHECK_STATUS(set_failures(c, 0xFu, &hover), TVMD_ERR_CONFIG_NO_AGENTS);
  CHECK_STATUS(set_failures(c, 0x3u, &hover), TVMD_ERR_CONFIG_RANK_DEFICIENT);
  CHECK_STATUS(tvmd_set_failures(c, 1u << 2, NULL), TVMD_OK); /* the mask in force */
  fprintf(record, "failures 4 0 - - - - -\n");
  for (i = 0; i < 4; ++i) {
    s = at_rest(0.0f, 0.01f * (float)i, 1.5f);
    r = hover_at(0.0f, 0.0f, 1.5f);
    CHECK_STATUS(step(c, &s, &r, &o), TVMD_OK);
    CHECK(o.commands[2].thrust == 0.0f && o.commands[2].omega == 0.0f);
    CHECK(o.commands[0].thrust + o.commands[1].thrust + o.commands[3].thrust > 0.0f);
  }
  test_actuators(c, &o, 1u << 2);
  CHECK_STATUS(set_failures(c, 0, &hover), TVMD_OK);
  CHECK(hover.capable);

  /* Reset: the held command becomes idle. */
  CHECK_STATUS(tvmd_reset(c), TVMD_OK);
  fprintf(record, "reset\n");
  s = at_rest(NAN, 0.0f, 1.5f);
  CHECK_STATUS(step(c, &s, &r, &o), TVMD_ERR_INPUT_NON_FINITE);
  CHECK(o.commands[0].thrust == 0.0f && o.commands[3].eta_y == 0.0f);
  s = at_rest(0.0f, 0.0f, 1.5f);
  CHECK_STATUS(step(c, &s, &r, &o), TVMD_OK);
  test_law();
  test_stages();
  test_fault();

  fclose(record);
  printf("tvmd C test: %d checks, %d failed\n", checks, failed);
  return failed == 0 ? 0 : 1;
}
