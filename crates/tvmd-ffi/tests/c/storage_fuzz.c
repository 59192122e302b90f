/* Storage corruption under a watchdog: whatever a stray write leaves in a created handle, no
 * entry point hangs or crashes. Every 8-byte word of the storage is overwritten with several
 * patterns (all zeros, all ones, 0x41 bytes, the word with one bit flipped, plus four words of
 * 0x41 from each word on), each case in a child process (fork) under alarm(): the child
 * calls the entry points of a control period on the corrupted handle, and the case passes when
 * the child exits normally within the time and either every call refused the handle
 * (TVMD_ERR_CORRUPTED, or TVMD_ERR_NOT_INITIALIZED for the head word) or the word was one no
 * entry point reads (the step then equals the intact handle's, bit for bit).
 *
 * Usage: storage_fuzz (built by scripts/ffi.sh with _POSIX_C_SOURCE for fork and alarm). */
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
#define PATTERNS 5

static TvmdController intact, work;
static TvmdOutput reference_out;

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

/* One control period's entry points on `c`: 0 when all refused it alike (`*refused` set to the
 * status), 1 when all accepted it (`*out` the step's output), -1 otherwise. */
static int period(TvmdController *c, TvmdOutput *out, TvmdStatus *refused) {
  TvmdState s = state();
  TvmdReference r = reference();
  TvmdActuatorMap map;
  TvmdActuatorOutputs act;
  TvmdHover hover;
  TvmdStatus st[5];
  int k;
  memset(out, 0, sizeof *out);
  out->size = sizeof *out;
  memset(&map, 0, sizeof map);
  map.size = sizeof map;
  memset(&act, 0, sizeof act);
  act.size = sizeof act;
  memset(&hover, 0, sizeof hover);
  hover.size = sizeof hover;
  st[0] = tvmd_set_landed(c, 0);
  st[1] = tvmd_step(c, &s, &r, out);
  st[2] = tvmd_actuator_map_default(c, &map);
  st[3] = st[2] == TVMD_OK ? tvmd_actuator_outputs(c, &map, out->commands, TVMD_MAX_AGENTS, &act)
                           : st[2];
  st[4] = tvmd_hover_capability(c, &hover);
  for (k = 1; k < 5; ++k) {
    if (st[k] != st[0]) return -1;
  }
  *refused = st[0];
  return st[0] == TVMD_OK ? 1 : 0;
}

static uint64_t pattern(uint64_t word, int p) {
  switch (p) {
    case 0: return 0;
    case 1: return ~(uint64_t)0;
    case 2: return 0x4141414141414141ull;
    case 3: return word ^ 1;
    default: return word ^ ((uint64_t)1 << 62);
  }
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
    TvmdOutput out;
    TvmdStatus refused = TVMD_OK;
    int s, verdict;
    alarm(WATCHDOG_SECONDS);
    memcpy(&work, &intact, sizeof work);
    for (s = 0; s < span && word + (size_t)s < TVMD_CONTROLLER_WORDS; ++s) {
      work.opaque[word + (size_t)s] = pattern(work.opaque[word + (size_t)s], p);
    }
    verdict = period(&work, &out, &refused);
    if (verdict == 0) {
      _exit(refused == TVMD_ERR_CORRUPTED || (word == 0 && refused == TVMD_ERR_NOT_INITIALIZED) ? 0 : 3);
    }
    if (verdict == 1) {
      /* Accepted: only a word no entry point reads, so the period is the intact handle's. */
      _exit(memcmp(out.commands, reference_out.commands, sizeof out.commands) == 0 ? 0 : 4);
    }
    _exit(5);
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
    fprintf(stderr, "word %zu pattern %d span %d: exit %d (3: a status other than "
            "CORRUPTED, 4: accepted with another output, 5: entry points disagree)\n",
            word, p, span, WEXITSTATUS(status));
  }
  return 1;
}

int main(void) {
  TvmdConfig config;
  TvmdStatus refused;
  size_t word;
  int p, failures = 0, cases = 0;
  memset(&config, 0, sizeof config);
  config.size = sizeof config;
  if (tvmd_config_default(&config) != TVMD_OK || tvmd_create(&intact, sizeof intact, &config) != TVMD_OK) {
    fprintf(stderr, "cannot create the controller\n");
    return 1;
  }
  /* One period first, so the handle holds commands, estimates and the allocator's state. */
  memcpy(&work, &intact, sizeof work);
  if (period(&intact, &reference_out, &refused) != 1 || period(&intact, &reference_out, &refused) != 1) {
    fprintf(stderr, "the intact handle does not fly: %s\n", tvmd_status_name(refused));
    return 1;
  }
  /* The reference output: the next period of an intact copy. */
  memcpy(&work, &intact, sizeof work);
  if (period(&work, &reference_out, &refused) != 1) {
    fprintf(stderr, "the intact copy does not fly\n");
    return 1;
  }
  /* The tail guard is the last word; every word before it is fuzzed. */
  for (word = 0; word + 1 < TVMD_CONTROLLER_WORDS; ++word) {
    for (p = 0; p < PATTERNS; ++p) {
      if (pattern(intact.opaque[word], p) == intact.opaque[word]) continue;
      failures += run_case(word, p, 1);
      ++cases;
    }
    failures += run_case(word, 2, 4);
    ++cases;
  }
  printf("storage fuzz: %d cases over %d words, %d failed\n", cases, (int)TVMD_CONTROLLER_WORDS - 1,
         failures);
  return failures == 0 ? 0 : 1;
}
