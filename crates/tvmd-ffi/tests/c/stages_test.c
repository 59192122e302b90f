/* The C test of the stages and the reconfiguration (run from tvmd_test.c's main): on two
 * handles of the same configuration, tvmd_law then tvmd_allocate gives tvmd_step's commands
 * bit for bit through a tilt the planner saturates on, and tvmd_compensation its offset-free
 * compensation; tvmd_plan plans for a force; a refused
 * reconfiguration leaves the controller stepping exactly as before; the setters, the seed
 * and the storage guards refuse bad input with a clean status. */
#include <math.h>
#include <string.h>

#include "check.h"

static TvmdController whole_storage, staged_storage;

static TvmdConfig paper(void) {
  TvmdConfig config;
  memset(&config, 0, sizeof config);
  config.size = sizeof config;
  CHECK_STATUS(tvmd_config_paper(&config), TVMD_OK);
  return config;
}

static TvmdReference tilted(float roll) {
  TvmdReference r = hover_at(0.0f, 0.0f, 1.5f);
  float c = cosf(roll), s = sinf(roll);
  r.attitude[4] = c;
  r.attitude[5] = -s;
  r.attitude[7] = s;
  r.attitude[8] = c;
  return r;
}

/* Returns the periods whose offset-free compensation (read from the staged handle with
 * tvmd_compensation, equal to the step's bit for bit) was not zero. With `all_lift`, every
 * agent lifts in every period (the paper's law). */
static int test_stages_match_the_step(TvmdController *whole, TvmdController *staged, int all_lift) {
  int k, a, moved = 0;
  for (k = 0; k < 30; ++k) {
    TvmdState s = at_rest(0.2f - 0.005f * (float)k, 0.0f, 1.5f);
    TvmdReference r = tilted(0.04f * (float)k);
    TvmdOutput o = empty_output();
    TvmdLawOutput law;
    TvmdAllocationOutput alloc;
    TvmdWrench w;
    TvmdCompensation comp;
    memset(&law, 0, sizeof law);
    law.size = sizeof law;
    memset(&alloc, 0, sizeof alloc);
    alloc.size = sizeof alloc;
    CHECK_STATUS(tvmd_step(whole, &s, &r, &o), TVMD_OK);
    CHECK_STATUS(tvmd_law(staged, &s, &r, &law), TVMD_OK);
    w.size = sizeof w;
    memcpy(w.torque, law.torque, sizeof w.torque);
    memcpy(w.force, law.force, sizeof w.force);
    CHECK_STATUS(tvmd_allocate(staged, &w, &alloc), TVMD_OK);
    CHECK(memcmp(alloc.commands, o.commands, sizeof o.commands) == 0);
    CHECK(memcmp(law.planned_attitude, o.planned_attitude, sizeof law.planned_attitude) == 0);
    CHECK(law.planner_status == o.planner_status);
    CHECK(alloc.force_error == o.e_f);
    for (a = 0; a < 4 && all_lift; ++a) CHECK(alloc.commands[a].thrust > 0.0f);
    memset(&comp, 0, sizeof comp);
    comp.size = sizeof comp;
    CHECK_STATUS(tvmd_compensation(staged, &comp), TVMD_OK);
    CHECK(memcmp(comp.force, o.compensation_force, sizeof comp.force) == 0);
    CHECK(memcmp(comp.torque, o.compensation_torque, sizeof comp.torque) == 0);
    moved += comp.force[0] != 0.0f || comp.force[1] != 0.0f || comp.force[2] != 0.0f;
  }
  return moved;
}

static void test_compensation_errors(TvmdController *c) {
  static TvmdController never;
  TvmdCompensation comp;
  memset(&comp, 0, sizeof comp);
  comp.size = 3;
  CHECK_STATUS(tvmd_compensation(c, &comp), TVMD_ERR_SIZE);
  CHECK(comp.force[0] == 0.0f); /* not written */
  comp.size = sizeof comp;
  CHECK_STATUS(tvmd_compensation(c, NULL), TVMD_ERR_NULL_POINTER);
  CHECK_STATUS(tvmd_compensation(NULL, &comp), TVMD_ERR_NULL_POINTER);
  CHECK_STATUS(tvmd_compensation(&never, &comp), TVMD_ERR_NOT_INITIALIZED);
  CHECK(isnan(comp.force[0]) && isnan(comp.torque[2]));
}

static void test_plan(TvmdController *c) {
  TvmdPlanOutput p;
  TvmdReference r = tilted(1.0f);
  float up[3] = {0.0f, 0.0f, 27.5f}, bad[9];
  memset(&p, 0, sizeof p);
  p.size = sizeof p;
  CHECK_STATUS(tvmd_plan(c, r.attitude, up, &p), TVMD_OK);
  /* pi/3 is beyond what A4-Inc holds at s = 0.5: the planner tilts back toward the force. */
  CHECK(p.planner_status == TVMD_PLANNER_PLANNED && p.theta > 0.0f);
  memcpy(bad, r.attitude, sizeof bad);
  bad[0] = 2.0f;
  CHECK_STATUS(tvmd_plan(c, bad, up, &p), TVMD_ERR_INPUT_NOT_ROTATION);
  CHECK(isnan(p.theta));
  CHECK_STATUS(tvmd_plan(c, NULL, up, &p), TVMD_ERR_NULL_POINTER);
}

static void test_reconfigure(TvmdController *a, TvmdController *b) {
  TvmdConfig bad = paper(), ok = paper();
  TvmdState s = at_rest(0.1f, 0.0f, 1.5f);
  TvmdReference r = hover_at(0.0f, 0.0f, 1.5f);
  TvmdOutput oa = empty_output(), ob = empty_output();
  TvmdAgentCommand seed[4];
  int i;
  bad.relaxation = 2.0f;
  CHECK_STATUS(tvmd_validate_config(&bad), TVMD_ERR_CONFIG_RELAXATION);
  CHECK_STATUS(tvmd_validate_config(&ok), TVMD_OK);
  CHECK_STATUS(tvmd_reconfigure(a, &bad), TVMD_ERR_CONFIG_RELAXATION);
  for (i = 0; i < 3; ++i) {
    CHECK_STATUS(tvmd_step(a, &s, &r, &oa), TVMD_OK);
    CHECK_STATUS(tvmd_step(b, &s, &r, &ob), TVMD_OK);
    CHECK(memcmp(oa.commands, ob.commands, sizeof oa.commands) == 0);
  }
  CHECK_STATUS(tvmd_set_relaxation(a, 1.5f), TVMD_ERR_CONFIG_RELAXATION);
  CHECK_STATUS(tvmd_set_relaxation(a, 0.5f), TVMD_OK);
  for (i = 0; i < 4; ++i) seed[i] = oa.commands[i];
  CHECK_STATUS(tvmd_seed_commands(a, seed, 4), TVMD_OK);
  seed[1].eta_x = 3.0f;
  CHECK_STATUS(tvmd_seed_commands(a, seed, 4), TVMD_ERR_INPUT_OUT_OF_RANGE);
  CHECK_STATUS(tvmd_seed_commands(a, seed, 16), TVMD_ERR_SIZE);
  CHECK_STATUS(tvmd_reconfigure(a, &ok), TVMD_OK);
  CHECK_STATUS(tvmd_check(a), TVMD_OK);
}

static void test_guards(void) {
  static TvmdController guarded;
  TvmdConfig config = paper();
  CHECK_STATUS(tvmd_check(&guarded), TVMD_ERR_NOT_INITIALIZED);
  CHECK_STATUS(tvmd_create(&guarded, sizeof guarded, &config), TVMD_OK);
  CHECK_STATUS(tvmd_check(&guarded), TVMD_OK);
  /* A neighbour's overrun into the last word. */
  guarded.opaque[TVMD_CONTROLLER_WORDS - 1] ^= 1u;
  CHECK_STATUS(tvmd_check(&guarded), TVMD_ERR_CORRUPTED);
  guarded.opaque[TVMD_CONTROLLER_WORDS - 1] ^= 1u;
  CHECK_STATUS(tvmd_check(&guarded), TVMD_OK);
}

void test_stages(void) {
  TvmdConfig config = paper();
  CHECK_STATUS(tvmd_create(&whole_storage, sizeof whole_storage, &config), TVMD_OK);
  CHECK_STATUS(tvmd_create(&staged_storage, sizeof staged_storage, &config), TVMD_OK);
  /* The paper's law has no offset-free action: the compensation stays zero. */
  CHECK(test_stages_match_the_step(&whole_storage, &staged_storage, 1) == 0);
  test_plan(&staged_storage);
  test_compensation_errors(&staged_storage);
  /* The default (offset-free) law: a state that does not follow the request moves it. */
  memset(&config, 0, sizeof config);
  config.size = sizeof config;
  CHECK_STATUS(tvmd_config_default(&config), TVMD_OK);
  CHECK_STATUS(tvmd_create(&whole_storage, sizeof whole_storage, &config), TVMD_OK);
  CHECK_STATUS(tvmd_create(&staged_storage, sizeof staged_storage, &config), TVMD_OK);
  CHECK(test_stages_match_the_step(&whole_storage, &staged_storage, 0) > 20);
  config = paper();
  CHECK_STATUS(tvmd_create(&whole_storage, sizeof whole_storage, &config), TVMD_OK);
  CHECK_STATUS(tvmd_create(&staged_storage, sizeof staged_storage, &config), TVMD_OK);
  test_reconfigure(&whole_storage, &staged_storage);
  test_guards();
}
