/* Storage corruption under a watchdog: whatever a stray write leaves in a created handle, no
 * entry point hangs or crashes, and each returns either TVMD_OK with finite outputs inside the
 * created configuration's admissible set, or an error status. Every 8-byte word of the storage
 * but the tail guard is overwritten with several patterns (all zeros, all ones, 0x41 bytes,
 * three single-bit flips, a random word), and from each word on four words of 0x41 and four
 * random words; each case runs in a child process (fork) under alarm(): the child calls the
 * entry points of two control periods (the cycle, the stages, the actuator outputs, the hover
 * classification, the failure mask) on the corrupted handle, and the case passes when the
 * child exits normally within the watchdog's time with every call's answer well formed.
 *
 * Usage: storage_fuzz [WORD PATTERN SPAN] (built by scripts/ffi.sh with _POSIX_C_SOURCE for
 * fork and alarm); with arguments, one case runs in this process (for a debugger). */
#include <math.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include "tvmd.h"

/* Seconds a child may take: one period costs well under a millisecond. */
#define WATCHDOG_SECONDS 5
#define PATTERNS 7
#define RANDOM_PATTERN 6
/* Relative slack on the admissible set's bounds (the inversion's own tolerance is 1e-5). */
#define SLACK 1e-4f

static TvmdController intact, work;
static TvmdConfig config;

static TvmdState state(void) {
  TvmdState s;
  memset(&s, 0, sizeof s);
  s.size = sizeof s;
  s.position[0] = 0.2f;
  s.position[2] = 1.5f;
  s.attitude[0] = s.attitude[4] = s.attitude[8] = 1.0f;
  return s;
}

static TvmdReference reference(void) {
  TvmdReference r;
  memset(&r, 0, sizeof r);
  r.size = sizeof r;
  r.position[2] = 1.5f;
  r.attitude[0] = r.attitude[4] = r.attitude[8] = 1.0f;
  return r;
}

/* 1 when `status` is one an entry point returns. */
static int known(TvmdStatus status) {
  return strcmp(tvmd_status_name(status), "TVMD_UNKNOWN_STATUS") != 0;
}

static int finite_all(const float *x, int n) {
  int k;
  for (k = 0; k < n; ++k) {
    if (!isfinite(x[k])) return 0;
  }
  return 1;
}

/* 1 when the `count` commands are finite and inside the created configuration's limits. */
static int admissible(const TvmdAgentCommand *c, uint32_t count) {
  const TvmdLimits *l = &config.limits;
  uint32_t k;
  if (count != config.agent_count) return 0;
  for (k = 0; k < count; ++k) {
    if (!finite_all(&c[k].eta_x, 4)) return 0;
    if (fabsf(c[k].eta_x) > l->sigma_x * (1 + SLACK) || fabsf(c[k].eta_y) > l->sigma_y * (1 + SLACK))
      return 0;
    if (c[k].thrust < 0 || c[k].thrust > l->max_thrust * (1 + SLACK) || c[k].omega < 0) return 0;
  }
  return 1;
}

/* One call's answer: 0 when well formed, else a line on stderr and 1. */
static int judge(const char *call, TvmdStatus status, int outputs_ok) {
  if (!known(status)) {
    fprintf(stderr, "  %s returned the unknown status %d\n", call, (int)status);
    return 1;
  }
  if (status == TVMD_OK && !outputs_ok) {
    fprintf(stderr, "  %s returned TVMD_OK with outputs outside the admissible set\n", call);
    return 1;
  }
  return 0;
}

/* Zeroes a struct and sets its `size`. */
#define SIZED(x) (memset(&(x), 0, sizeof(x)), (x).size = sizeof(x))

/* Two control periods' entry points on `c`: the number of ill-formed answers. */
static int periods(TvmdController *c) {
  TvmdState s = state();
  TvmdReference r = reference();
  TvmdOutput out;
  TvmdLawOutput law;
  TvmdWrench wrench;
  TvmdAllocationOutput alloc;
  TvmdPlanOutput plan;
  TvmdActuatorMap map;
  TvmdActuatorOutputs act;
  TvmdHover hover;
  TvmdCompensation comp;
  TvmdStatus st;
  int bad = 0, period;
  for (period = 0; period < 2; ++period) {
    SIZED(out);
    SIZED(law);
    SIZED(wrench);
    SIZED(alloc);
    SIZED(plan);
    SIZED(map);
    SIZED(act);
    SIZED(hover);
    SIZED(comp);
    bad += judge("tvmd_check", tvmd_check(c), 1);
    bad += judge("tvmd_set_landed", tvmd_set_landed(c, 0), 1);
    st = tvmd_step(c, &s, &r, &out);
    bad += judge("tvmd_step", st,
                 admissible(out.commands, out.agent_count) && isfinite(out.e_f) &&
                     finite_all(out.planned_attitude, 9) && isfinite(out.planner_theta) &&
                     finite_all(out.compensation_force, 3) && finite_all(out.compensation_torque, 3));
    st = tvmd_law(c, &s, &r, &law);
    bad += judge("tvmd_law", st, finite_all(law.torque, 3) && finite_all(law.force, 3) &&
                                     finite_all(law.planned_attitude, 9));
    memcpy(wrench.torque, law.torque, sizeof wrench.torque);
    memcpy(wrench.force, law.force, sizeof wrench.force);
    if (st == TVMD_OK) {
      st = tvmd_allocate(c, &wrench, &alloc);
      bad += judge("tvmd_allocate", st, admissible(alloc.commands, alloc.agent_count) &&
                                            isfinite(alloc.force_error) && isfinite(alloc.torque_error));
    }
    st = tvmd_plan(c, r.attitude, wrench.force, &plan);
    bad += judge("tvmd_plan", st, finite_all(plan.planned_attitude, 9) && isfinite(plan.theta));
    st = tvmd_actuator_map_default(c, &map);
    bad += judge("tvmd_actuator_map_default", st, 1);
    if (st == TVMD_OK) {
      st = tvmd_actuator_outputs(c, &map, out.commands, TVMD_MAX_AGENTS, &act);
      bad += judge("tvmd_actuator_outputs", st, 1);
    }
    st = tvmd_compensation(c, &comp);
    bad += judge("tvmd_compensation", st, finite_all(comp.force, 3) && finite_all(comp.torque, 3));
    st = tvmd_hover_capability(c, &hover);
    bad += judge("tvmd_hover_capability", st, isfinite(hover.margin) && isfinite(hover.weight));
    st = tvmd_set_failures(c, period == 0 ? 1u : 0u, &hover);
    bad += judge("tvmd_set_failures", st, isfinite(hover.margin) && isfinite(hover.weight));
  }
  return bad;
}

static uint64_t random_word(uint64_t *seed) {
  /* xorshift64 */
  uint64_t x = *seed;
  x ^= x << 13;
  x ^= x >> 7;
  x ^= x << 17;
  return *seed = x;
}

static uint64_t pattern(uint64_t word, int p, uint64_t *seed) {
  switch (p) {
    case 0: return 0;
    case 1: return ~(uint64_t)0;
    case 2: return 0x4141414141414141ull;
    case 3: return word ^ 1;
    case 4: return word ^ ((uint64_t)1 << 30);
    case 5: return word ^ ((uint64_t)1 << 62);
    default: return random_word(seed);
  }
}

/* Corrupts `span` words from `word` on with pattern `p` and runs the periods: the number of
 * ill-formed answers. */
static int corrupted_periods(size_t word, int p, int span) {
  uint64_t seed = 0x9e3779b97f4a7c15ull ^ ((uint64_t)word << 8) ^ (uint64_t)p ^ ((uint64_t)span << 4);
  int s;
  memcpy(&work, &intact, sizeof work);
  for (s = 0; s < span && word + (size_t)s + 1 < TVMD_CONTROLLER_WORDS; ++s) {
    work.opaque[word + (size_t)s] = pattern(work.opaque[word + (size_t)s], p, &seed);
  }
  return periods(&work);
}

/* Runs one case in a child under the watchdog: 0 = passed, else a description printed. */
static int run_case(size_t word, int p, int span) {
  pid_t pid;
  int status;
  fflush(stdout);
  fflush(stderr);
  pid = fork();
  if (pid < 0) {
    perror("fork");
    exit(2);
  }
  if (pid == 0) {
    alarm(WATCHDOG_SECONDS);
    _exit(corrupted_periods(word, p, span) == 0 ? 0 : 3);
  }
  if (waitpid(pid, &status, 0) != pid) {
    perror("waitpid");
    exit(2);
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return 0;
  if (WIFSIGNALED(status)) {
    fprintf(stderr, "word %zu pattern %d span %d: killed by signal %d%s\n", word, p, span,
            WTERMSIG(status), WTERMSIG(status) == SIGALRM ? " (the watchdog: a hang)" : "");
  } else {
    fprintf(stderr, "word %zu pattern %d span %d: an ill-formed answer (above)\n", word, p, span);
  }
  return 1;
}

int main(int argc, char **argv) {
  size_t word;
  int p, failures = 0, cases = 0;
  memset(&config, 0, sizeof config);
  config.size = sizeof config;
  if (tvmd_config_default(&config) != TVMD_OK || tvmd_create(&intact, sizeof intact, &config) != TVMD_OK) {
    fprintf(stderr, "cannot create the controller\n");
    return 1;
  }
  /* The intact handle answers every call well (the fuzz's own check), and after a period it
   * holds commands, estimates and the allocator's state. */
  memcpy(&work, &intact, sizeof work);
  if (periods(&work) != 0) {
    fprintf(stderr, "the intact handle answers ill\n");
    return 1;
  }
  memcpy(&intact, &work, sizeof work);
  if (argc == 4) {
    return corrupted_periods((size_t)strtoul(argv[1], NULL, 10), atoi(argv[2]), atoi(argv[3])) == 0 ? 0 : 1;
  }
  /* The tail guard is the last word; every word before it is fuzzed. */
  for (word = 0; word + 1 < TVMD_CONTROLLER_WORDS; ++word) {
    uint64_t seed = 1;
    for (p = 0; p < PATTERNS; ++p) {
      if (p != RANDOM_PATTERN && pattern(intact.opaque[word], p, &seed) == intact.opaque[word]) continue;
      failures += run_case(word, p, 1);
      ++cases;
    }
    failures += run_case(word, 2, 4);
    failures += run_case(word, RANDOM_PATTERN, 4);
    cases += 2;
  }
  printf("storage fuzz: %d cases over %d words, %d failed\n", cases, (int)TVMD_CONTROLLER_WORDS - 1,
         failures);
  return failures == 0 ? 0 : 1;
}
