/* The C test of agent fault detection (run from tvmd_test.c's main): off in both library
 * configurations (the report says no verdict); on with the default (observer) law it reports
 * a nominal hover below its threshold; it needs the observer; bad numbers and modes give their
 * status, those of the agents' reports' check (`fault.reports`) too. The loss scenarios themselves are flown by the simulator's tests (full dynamics). */
#include <math.h>
#include <string.h>

#include "check.h"

static TvmdController fault_storage, plain_storage;

static TvmdFaultReport report_of(TvmdController *c);

/* Agent `agent`'s report of the command `c`, measured `age` s ago (`dead`: its rotor stopped),
 * in the rpm of the configuration's rotor model (normalized: 6000 rpm at the maximum thrust). */
static TvmdStatus report_agent(TvmdController *h, const TvmdConfig *config, unsigned agent,
                               TvmdAgentCommand c, int dead, float age) {
  TvmdAgentReport rep;
  memset(&rep, 0, sizeof rep);
  rep.size = sizeof rep;
  rep.agent = agent;
  if (config->limits.rotor_model == TVMD_ROTOR_NORMALIZED) {
    rep.max_rpm = 6000.0f;
    rep.rpm = dead ? 0.0f : c.omega * 6000.0f;
  } else {
    rep.rpm = dead ? 0.0f : c.omega * 60.0f / (2.0f * 3.14159265f);
  }
  rep.eta_x = c.eta_x;
  rep.eta_y = c.eta_y;
  rep.age = age;
  return tvmd_set_agent_report(h, &rep);
}

/* Agents' reports (esc_status rpm, servo feedback): agreeing ones change nothing; agent 1's
 * rotor reported stopped is confirmed lost from the reports and masked; bad reports give their
 * status; without detection the reports are refused. */
static void test_agent_reports(TvmdConfig config) {
  TvmdState s = at_rest(0.0f, 0.0f, 1.5f);
  TvmdReference r = hover_at(0.0f, 0.0f, 1.5f);
  TvmdOutput o = empty_output(), plain = empty_output();
  TvmdFaultReport rep;
  TvmdAgentReport bad;
  unsigned i;
  int k;
  config.fault.mode = TVMD_FAULT_MASK;
  CHECK_STATUS(tvmd_create(&fault_storage, sizeof fault_storage, &config), TVMD_OK);
  CHECK_STATUS(tvmd_create(&plain_storage, sizeof plain_storage, &config), TVMD_OK);
  for (k = 0; k < 20; ++k) {
    if (k > 0)
      for (i = 0; i < o.agent_count; ++i)
        CHECK_STATUS(report_agent(&fault_storage, &config, i, o.commands[i], 0, 0.01f), TVMD_OK);
    CHECK_STATUS(tvmd_step(&fault_storage, &s, &r, &o), TVMD_OK);
    CHECK_STATUS(tvmd_step(&plain_storage, &s, &r, &plain), TVMD_OK);
    CHECK(memcmp(&o.commands, &plain.commands, sizeof o.commands) == 0);
  }
  rep = report_of(&fault_storage);
  CHECK(rep.verdict == TVMD_FAULT_VERDICT_NOMINAL && rep.source == TVMD_FAULT_SOURCE_NONE);
  /* Agent 1 reports its rotor stopped: two reports confirm the loss; the mask follows. */
  for (k = 0; k < 3; ++k) {
    for (i = 0; i < o.agent_count; ++i)
      CHECK_STATUS(report_agent(&fault_storage, &config, i, o.commands[i], i == 1u, 0.01f), TVMD_OK);
    CHECK_STATUS(tvmd_step(&fault_storage, &s, &r, &o), TVMD_OK);
    rep = report_of(&fault_storage);
    if (rep.masked_agent == 1) break;
  }
  CHECK(k == 1);
  CHECK(rep.verdict == TVMD_FAULT_VERDICT_CONFIRMED && rep.agent == 1);
  CHECK(rep.kind == TVMD_FAULT_KIND_LOSS && rep.source == TVMD_FAULT_SOURCE_REPORTS);
  CHECK(o.commands[1].thrust == 0.0f);
  /* With a persistence of four reports the same loss is confirmed two reports later. */
  config.fault.reports.persistence = 4u;
  CHECK_STATUS(tvmd_create(&plain_storage, sizeof plain_storage, &config), TVMD_OK);
  for (k = 0; k < 20; ++k) { /* agreeing reports while the check's rotor model spins up */
    if (k > 0)
      for (i = 0; i < plain.agent_count; ++i)
        CHECK_STATUS(report_agent(&plain_storage, &config, i, plain.commands[i], 0, 0.01f), TVMD_OK);
    CHECK_STATUS(tvmd_step(&plain_storage, &s, &r, &plain), TVMD_OK);
  }
  for (k = 0; k < 5; ++k) {
    for (i = 0; i < plain.agent_count; ++i)
      CHECK_STATUS(report_agent(&plain_storage, &config, i, plain.commands[i], i == 1u, 0.01f), TVMD_OK);
    CHECK_STATUS(tvmd_step(&plain_storage, &s, &r, &plain), TVMD_OK);
    rep = report_of(&plain_storage);
    if (rep.masked_agent == 1) break;
  }
  CHECK(k == 3 && rep.source == TVMD_FAULT_SOURCE_REPORTS);
  config.fault.reports.persistence = 2u;
  /* Bad reports. */
  memset(&bad, 0, sizeof bad);
  CHECK_STATUS(tvmd_set_agent_report(&fault_storage, NULL), TVMD_ERR_NULL_POINTER);
  CHECK_STATUS(tvmd_set_agent_report(&fault_storage, &bad), TVMD_ERR_SIZE);
  bad.size = sizeof bad;
  CHECK_STATUS(tvmd_set_agent_report(NULL, &bad), TVMD_ERR_NULL_POINTER);
  bad.agent = o.agent_count;
  CHECK_STATUS(tvmd_set_agent_report(&fault_storage, &bad), TVMD_ERR_REPORT_AGENT);
  bad.agent = 0u;
  bad.rpm = NAN;
  CHECK_STATUS(tvmd_set_agent_report(&fault_storage, &bad), TVMD_ERR_INPUT_NON_FINITE);
  bad.rpm = -1.0f;
  CHECK_STATUS(tvmd_set_agent_report(&fault_storage, &bad), TVMD_ERR_INPUT_OUT_OF_RANGE);
  bad.rpm = 100.0f;
  bad.age = -0.1f;
  CHECK_STATUS(tvmd_set_agent_report(&fault_storage, &bad), TVMD_ERR_INPUT_OUT_OF_RANGE);
  bad.age = 0.0f;
  bad.max_rpm = INFINITY;
  CHECK_STATUS(tvmd_set_agent_report(&fault_storage, &bad), TVMD_ERR_INPUT_NON_FINITE);
  bad.max_rpm = 0.0f;
  CHECK_STATUS(tvmd_set_agent_report(&fault_storage, &bad), TVMD_OK);
  CHECK(strcmp(tvmd_status_name(TVMD_ERR_REPORT_AGENT), "TVMD_ERR_REPORT_AGENT") == 0);
  config.fault.mode = TVMD_FAULT_OFF;
  CHECK_STATUS(tvmd_create(&plain_storage, sizeof plain_storage, &config), TVMD_OK);
  CHECK_STATUS(tvmd_set_agent_report(&plain_storage, &bad), TVMD_ERR_REPORT_DETECTION_OFF);
}

static TvmdFaultReport report_of(TvmdController *c) {
  TvmdFaultReport r;
  memset(&r, 0, sizeof r);
  r.size = sizeof r;
  CHECK_STATUS(tvmd_fault_report(c, &r), TVMD_OK);
  return r;
}

void test_fault(void) {
  TvmdConfig config, bad;
  TvmdState s = at_rest(0.0f, 0.0f, 1.5f);
  TvmdReference r = hover_at(0.0f, 0.0f, 1.5f);
  TvmdOutput o = empty_output();
  TvmdFaultReport rep;
  int k;
  memset(&config, 0, sizeof config);
  config.size = sizeof config;
  CHECK_STATUS(tvmd_config_default(&config), TVMD_OK);
  /* Off, with the recommended numbers ready. */
  CHECK(config.fault.mode == TVMD_FAULT_OFF);
  CHECK(config.fault.model_error > 0.0f && config.fault.threshold > 0.0f);
  CHECK(config.fault.persistence >= 1u);
  CHECK_STATUS(tvmd_create(&fault_storage, sizeof fault_storage, &config), TVMD_OK);
  CHECK_STATUS(tvmd_step(&fault_storage, &s, &r, &o), TVMD_OK);
  rep = report_of(&fault_storage);
  CHECK(rep.verdict == TVMD_FAULT_VERDICT_NONE && rep.agent == -1 && isnan(rep.statistic));
  CHECK(rep.masked_agent == -1 && rep.masked_hover_capable == 0u);

  /* On: a steady hover is nominal, its statistic below the threshold. */
  config.fault.mode = TVMD_FAULT_MASK;
  CHECK_STATUS(tvmd_create(&fault_storage, sizeof fault_storage, &config), TVMD_OK);
  for (k = 0; k < 20; ++k) CHECK_STATUS(tvmd_step(&fault_storage, &s, &r, &o), TVMD_OK);
  rep = report_of(&fault_storage);
  CHECK(rep.verdict == TVMD_FAULT_VERDICT_NOMINAL);
  CHECK(rep.statistic >= 0.0f && rep.statistic < rep.threshold);
  CHECK(rep.threshold == config.fault.threshold);
  CHECK(rep.agent == -1 && rep.kind == TVMD_FAULT_KIND_NONE && rep.masked_agent == -1);

  /* It reads the observer's residual: the paper's law has none. */
  memset(&bad, 0, sizeof bad);
  bad.size = sizeof bad;
  CHECK_STATUS(tvmd_config_paper(&bad), TVMD_OK);
  bad.fault.mode = TVMD_FAULT_REPORT;
  CHECK_STATUS(tvmd_create(&fault_storage, sizeof fault_storage, &bad), TVMD_ERR_CONFIG_PARAMETER);
  bad = config; bad.fault.mode = 3;
  CHECK_STATUS(tvmd_create(&fault_storage, sizeof fault_storage, &bad), TVMD_ERR_ENUM_VALUE);
  bad = config; bad.fault.model_error = 0.0f;
  CHECK_STATUS(tvmd_create(&fault_storage, sizeof fault_storage, &bad), TVMD_ERR_CONFIG_PARAMETER);
  bad = config; bad.fault.threshold = NAN;
  CHECK_STATUS(tvmd_create(&fault_storage, sizeof fault_storage, &bad), TVMD_ERR_CONFIG_NON_FINITE);
  bad = config; bad.fault.persistence = 0u;
  CHECK_STATUS(tvmd_create(&fault_storage, sizeof fault_storage, &bad), TVMD_ERR_CONFIG_PARAMETER);
  /* The report check's settings: recommended in both configurations, refused when bad. */
  CHECK(config.fault.reports.thrust_tolerance == 0.1f && config.fault.reports.persistence == 2u);
  CHECK(config.fault.reports.link_timeout == 0.1f && config.fault.reports.command_delay == 0.01f);
  CHECK(config.fault.reports.servo_rate == 6.0f && config.fault.reports.servo_lag == 0.05f);
  CHECK(config.fault.reports.angle_tolerance == 0.05f);
  CHECK(config.fault.reports.thrust_forget == 2.5f && config.fault.reports.angle_forget == 2.5f);
  CHECK_STATUS(tvmd_config_paper(&bad), TVMD_OK);
  CHECK(memcmp(&bad.fault.reports, &config.fault.reports, sizeof bad.fault.reports) == 0);
  bad = config; bad.fault.reports.thrust_tolerance = 0.0f;
  CHECK_STATUS(tvmd_create(&fault_storage, sizeof fault_storage, &bad), TVMD_ERR_CONFIG_PARAMETER);
  bad = config; bad.fault.reports.angle_tolerance = NAN;
  CHECK_STATUS(tvmd_create(&fault_storage, sizeof fault_storage, &bad), TVMD_ERR_CONFIG_NON_FINITE);
  bad = config; bad.fault.reports.servo_rate = -6.0f;
  CHECK_STATUS(tvmd_create(&fault_storage, sizeof fault_storage, &bad), TVMD_ERR_CONFIG_PARAMETER);
  bad = config; bad.fault.reports.servo_lag = INFINITY;
  CHECK_STATUS(tvmd_create(&fault_storage, sizeof fault_storage, &bad), TVMD_ERR_CONFIG_NON_FINITE);
  bad = config; bad.fault.reports.command_delay = -0.01f;
  CHECK_STATUS(tvmd_create(&fault_storage, sizeof fault_storage, &bad), TVMD_ERR_CONFIG_PARAMETER);
  bad = config; bad.fault.reports.link_timeout = 0.0f;
  CHECK_STATUS(tvmd_create(&fault_storage, sizeof fault_storage, &bad), TVMD_ERR_CONFIG_PARAMETER);
  bad = config; bad.fault.reports.persistence = 0u;
  CHECK_STATUS(tvmd_create(&fault_storage, sizeof fault_storage, &bad), TVMD_ERR_CONFIG_PARAMETER);
  bad = config; bad.fault.reports.persistence = 256u;
  CHECK_STATUS(tvmd_create(&fault_storage, sizeof fault_storage, &bad), TVMD_ERR_CONFIG_PARAMETER);
  bad = config; bad.fault.reports.thrust_forget = 0.0f;
  CHECK_STATUS(tvmd_create(&fault_storage, sizeof fault_storage, &bad), TVMD_ERR_CONFIG_PARAMETER);
  bad = config; bad.fault.reports.angle_forget = NAN;
  CHECK_STATUS(tvmd_create(&fault_storage, sizeof fault_storage, &bad), TVMD_ERR_CONFIG_NON_FINITE);
  /* Off, the report check is not read. */
  bad.fault.mode = TVMD_FAULT_OFF;
  CHECK_STATUS(tvmd_create(&fault_storage, sizeof fault_storage, &bad), TVMD_OK);

  /* The report's own checks. */
  memset(&rep, 0, sizeof rep);
  CHECK_STATUS(tvmd_fault_report(&fault_storage, NULL), TVMD_ERR_NULL_POINTER);
  CHECK_STATUS(tvmd_fault_report(&fault_storage, &rep), TVMD_ERR_SIZE);
  rep.size = sizeof rep;
  CHECK_STATUS(tvmd_fault_report(NULL, &rep), TVMD_ERR_NULL_POINTER);
  test_agent_reports(config);
}
