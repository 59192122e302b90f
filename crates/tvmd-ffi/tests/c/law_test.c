/* The C test of the law beyond the paper (run from tvmd_test.c's main): tvmd_config_default
 * is the offset-free law and differs from tvmd_config_paper in the law's modes only; under a
 * constant unmodelled force in a crude hover loop the observer's compensation converges to
 * the force's negative and the position error vanishes, where the paper's law is left off;
 * tvmd_set_landed holds the compensation at zero; bad law values give their status. Steps of
 * the default law are recorded ("create default", "landed N") for the bit-for-bit replay. */
#include <math.h>
#include <string.h>

#include "check.h"

static TvmdController law_storage; /* zero-initialized: not initialized */

static TvmdConfig filled(TvmdStatus (*fill)(TvmdConfig *)) {
  TvmdConfig config;
  memset(&config, 0, sizeof config);
  config.size = sizeof config;
  CHECK_STATUS(fill(&config), TVMD_OK);
  return config;
}

static void set_landed(TvmdController *c, uint32_t landed) {
  CHECK_STATUS(tvmd_set_landed(c, landed), TVMD_OK);
  fprintf(record, "landed %u\n", (unsigned)landed);
}

/* The inertial force of the commands with the attitude at identity: sum of R_z(psi_i) T_i
 * a_hat(eta_x, eta_y) (eqs. 1, 4). */
static void team_force(const TvmdConfig *config, const TvmdOutput *o, float f[3]) {
  uint32_t i;
  f[0] = f[1] = f[2] = 0.0f;
  for (i = 0; i < config->agent_count; ++i) {
    const TvmdAgentCommand *c = &o->commands[i];
    float a[3], b[3];
    int q = ((config->agents[i].quarter_turns % 4) + 4) % 4;
    a[0] = c->thrust * cosf(c->eta_x) * sinf(c->eta_y);
    a[1] = -c->thrust * sinf(c->eta_x);
    a[2] = c->thrust * cosf(c->eta_x) * cosf(c->eta_y);
    b[2] = a[2];
    b[0] = q == 0 ? a[0] : q == 1 ? -a[1] : q == 2 ? -a[0] : a[1];
    b[1] = q == 0 ? a[1] : q == 1 ? a[0] : q == 2 ? -a[1] : -a[0];
    f[0] += b[0];
    f[1] += b[1];
    f[2] += b[2];
  }
}

/* A crude hover at 1.5 m under the constant unmodelled force d (N, inertial), the attitude
 * held at identity; the translation integrated from the commands' force. Switches the landed
 * flag off at period take_off (none if negative); counts the periods whose compensation was
 * exactly zero before it. Returns the final position error (m); *out is the last output. */
static float hover_under(TvmdController *c, const TvmdConfig *config, const float d[3],
                         int periods, int take_off, int *zero_while_landed, TvmdOutput *out) {
  const float dt = config->period, goal = 1.5f;
  float mass = config->navigator_mass, x[3] = {0.0f, 0.0f, goal}, v[3] = {0.0f, 0.0f, 0.0f};
  TvmdReference r = hover_at(0.0f, 0.0f, goal);
  uint32_t i;
  int k, j;
  for (i = 0; i < config->agent_count; ++i) mass += config->agents[i].mass;
  for (k = 0; k < periods; ++k) {
    TvmdState s = at_rest(x[0], x[1], x[2]);
    float f[3];
    memcpy(s.velocity, v, sizeof v);
    if (k == take_off) set_landed(c, 0);
    CHECK_STATUS(step(c, &s, &r, out), TVMD_OK);
    if (zero_while_landed && k < take_off) {
      *zero_while_landed += out->compensation_force[0] == 0.0f &&
                            out->compensation_force[1] == 0.0f &&
                            out->compensation_force[2] == 0.0f &&
                            out->compensation_torque[0] == 0.0f;
    }
    team_force(config, out, f);
    f[2] -= mass * config->gravity;
    for (j = 0; j < 3; ++j) {
      v[j] += (f[j] + d[j]) / mass * dt;
      x[j] += v[j] * dt;
    }
  }
  return sqrtf(x[0] * x[0] + x[1] * x[1] + (x[2] - goal) * (x[2] - goal));
}

static float distance_to_minus(const float compensation[3], const float d[3]) {
  float e0 = compensation[0] + d[0], e1 = compensation[1] + d[1], e2 = compensation[2] + d[2];
  return sqrtf(e0 * e0 + e1 * e1 + e2 * e2);
}

static void test_configs(void) {
  TvmdConfig def = filled(tvmd_config_default), paper = filled(tvmd_config_paper), bad;
  CHECK(TVMD_ABI_VERSION == 5 && tvmd_abi_version() == 5);
  CHECK_STATUS(tvmd_config_default(NULL), TVMD_ERR_NULL_POINTER);
  bad = def;
  bad.size = sizeof bad - 4;
  CHECK_STATUS(tvmd_config_default(&bad), TVMD_ERR_SIZE);
  /* The default: natural gains, the observer, the planned rates, the library's numbers. */
  CHECK(def.law.gain_schedule == TVMD_GAINS_NATURAL);
  CHECK(def.law.offset_free == TVMD_OFFSET_FREE_OBSERVER);
  CHECK(def.law.attitude_rate != 0);
  CHECK(def.law.position_frequency[0] == 1.5f && def.law.position_frequency[2] == 1.5f);
  CHECK(def.law.attitude_frequency[1] == 6.0f && def.law.attitude_damping[2] == 0.6f);
  CHECK(def.law.position_damping[0] == 1.0f);
  CHECK(def.law.force_bandwidth == 10.0f && def.law.torque_bandwidth == 10.0f);
  CHECK(def.law.max_torque == 5.0f);
  CHECK(def.law.attitude_rate_bandwidth == 20.0f && def.law.attitude_rate_max == 5.0f);
  /* The paper: every mode off, everything else as the default. */
  CHECK(paper.law.gain_schedule == TVMD_GAINS_AS_GIVEN);
  CHECK(paper.law.offset_free == TVMD_OFFSET_FREE_OFF && paper.law.attitude_rate == 0);
  def.law.gain_schedule = TVMD_GAINS_AS_GIVEN;
  def.law.offset_free = TVMD_OFFSET_FREE_OFF;
  def.law.attitude_rate = 0;
  CHECK(memcmp(&def, &paper, sizeof def) == 0);
}

static void test_bad_values(void) {
  const TvmdConfig def = filled(tvmd_config_default);
  TvmdConfig bad;
  TvmdController *c = &law_storage;
  bad = def; bad.law.gain_schedule = 3;
  CHECK_STATUS(tvmd_create(c, sizeof *c, &bad), TVMD_ERR_ENUM_VALUE);
  bad = def; bad.law.offset_free = 9;
  CHECK_STATUS(tvmd_create(c, sizeof *c, &bad), TVMD_ERR_ENUM_VALUE);
  bad = def; bad.law.position_damping[1] = 0.0f;
  CHECK_STATUS(tvmd_create(c, sizeof *c, &bad), TVMD_ERR_CONFIG_PARAMETER);
  bad = def; bad.law.attitude_frequency[2] = NAN;
  CHECK_STATUS(tvmd_create(c, sizeof *c, &bad), TVMD_ERR_CONFIG_NON_FINITE);
  bad = def; bad.law.position_frequency[0] = 1e20f; /* K_x = m_C w^2 overflows */
  CHECK_STATUS(tvmd_create(c, sizeof *c, &bad), TVMD_ERR_CONFIG_NON_FINITE);
  bad = def; bad.law.force_bandwidth = -10.0f;
  CHECK_STATUS(tvmd_create(c, sizeof *c, &bad), TVMD_ERR_CONFIG_PARAMETER);
  bad = def; bad.law.max_torque = INFINITY;
  CHECK_STATUS(tvmd_create(c, sizeof *c, &bad), TVMD_ERR_CONFIG_NON_FINITE);
  bad = def; bad.law.attitude_rate_max = 0.0f;
  CHECK_STATUS(tvmd_create(c, sizeof *c, &bad), TVMD_ERR_CONFIG_PARAMETER);
  bad = def; bad.law.offset_free = TVMD_OFFSET_FREE_INTEGRAL; /* integral gains left zero */
  CHECK_STATUS(tvmd_create(c, sizeof *c, &bad), TVMD_ERR_CONFIG_PARAMETER);
  /* A refused create leaves the handle not initialized. */
  CHECK_STATUS(tvmd_set_landed(c, 1), TVMD_ERR_NOT_INITIALIZED);
  CHECK_STATUS(tvmd_set_landed(NULL, 1), TVMD_ERR_NULL_POINTER);
  /* A mode that is off ignores its numbers; the other modes create. */
  bad = def;
  bad.law.gain_schedule = TVMD_GAINS_TEAM_SCALED;
  bad.law.position_frequency[0] = NAN;
  bad.law.offset_free = TVMD_OFFSET_FREE_INTEGRAL;
  bad.law.integral_k_x[0] = bad.law.integral_k_x[1] = bad.law.integral_k_x[2] = 0.5f;
  bad.law.integral_k_r[0] = bad.law.integral_k_r[1] = bad.law.integral_k_r[2] = 0.2f;
  bad.law.force_bandwidth = -1.0f;
  bad.law.attitude_rate = 0;
  bad.law.attitude_rate_bandwidth = NAN;
  CHECK_STATUS(tvmd_create(c, sizeof *c, &bad), TVMD_OK);
}

void test_law(void) {
  const float d[3] = {0.8f, -0.5f, -1.5f};
  TvmdConfig def, paper;
  TvmdController *c = &law_storage;
  TvmdOutput o = empty_output();
  TvmdState s;
  TvmdReference r = hover_at(0.0f, 0.0f, 1.5f);
  float error;
  int zero = 0;

  test_configs();
  test_bad_values();
  def = filled(tvmd_config_default);
  paper = filled(tvmd_config_paper);

  /* The paper's law under the force: no compensation, left far off. */
  CHECK_STATUS(tvmd_create(c, sizeof *c, &paper), TVMD_OK);
  fprintf(record, "create\n");
  error = hover_under(c, &paper, d, 600, -1, NULL, &o);
  CHECK(error > 0.3f);
  CHECK(o.compensation_force[0] == 0.0f && o.compensation_force[2] == 0.0f);

  /* The default law, landed for the first second: compensation held at zero; after take-off
   * the observer's compensation converges to -d and the error vanishes. Recorded. */
  CHECK_STATUS(tvmd_create(c, sizeof *c, &def), TVMD_OK);
  fprintf(record, "create default\n");
  set_landed(c, 1);
  error = hover_under(c, &def, d, 600, 100, &zero, &o);
  CHECK(zero == 100);
  CHECK(distance_to_minus(o.compensation_force, d) < 0.02f);
  CHECK(fabsf(o.compensation_torque[0]) < 5.0f); /* within the bound */
  CHECK(error < 0.01f);

  /* A refused cycle: commands held, compensation NaN (not computed). */
  s = at_rest(NAN, 0.0f, 1.5f);
  CHECK_STATUS(step(c, &s, &r, &o), TVMD_ERR_INPUT_NON_FINITE);
  CHECK(diagnostics_nan(&o));

  /* Touch-down: zero at once, and reset keeps the flag. */
  set_landed(c, 1);
  CHECK_STATUS(tvmd_reset(c), TVMD_OK);
  fprintf(record, "reset\n");
  s = at_rest(0.1f, 0.0f, 1.4f);
  CHECK_STATUS(step(c, &s, &r, &o), TVMD_OK);
  CHECK(o.compensation_force[0] == 0.0f && o.compensation_force[1] == 0.0f &&
        o.compensation_force[2] == 0.0f && o.compensation_torque[2] == 0.0f);
}
