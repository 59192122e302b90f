/* The C test of agent fault detection (run from tvmd_test.c's main): off in both library
 * configurations (the report says no verdict); on with the default (observer) law it reports
 * a nominal hover below its threshold; it needs the observer; bad numbers and modes give their
 * status. The loss scenarios themselves are flown by the simulator's tests (full dynamics). */
#include <math.h>
#include <string.h>

#include "check.h"

static TvmdController fault_storage;

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

  /* The report's own checks. */
  memset(&rep, 0, sizeof rep);
  CHECK_STATUS(tvmd_fault_report(&fault_storage, NULL), TVMD_ERR_NULL_POINTER);
  CHECK_STATUS(tvmd_fault_report(&fault_storage, &rep), TVMD_ERR_SIZE);
  rep.size = sizeof rep;
  CHECK_STATUS(tvmd_fault_report(NULL, &rep), TVMD_ERR_NULL_POINTER);
}
