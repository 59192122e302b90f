/* What the files of the C test share (tvmd_test.c: main, the paper's law; law_test.c: the
 * default, offset-free law): the check counters and macros, the record file, and helpers. */
#ifndef TVMD_TEST_CHECK_H
#define TVMD_TEST_CHECK_H

#include <stdio.h>

#include "tvmd.h"

extern int checks;
extern int failed;
/* The record the Rust test crates/tvmd-ffi/tests/c_record.rs replays. */
extern FILE *record;

#define CHECK(cond)                                                              \
  do {                                                                           \
    ++checks;                                                                    \
    if (!(cond)) {                                                               \
      ++failed;                                                                  \
      fprintf(stderr, "%s:%d: check failed: %s\n", __FILE__, __LINE__, #cond);   \
    }                                                                            \
  } while (0)

#define CHECK_STATUS(call, expected)                                             \
  do {                                                                           \
    TvmdStatus got_ = (call);                                                    \
    ++checks;                                                                    \
    if (got_ != (expected)) {                                                    \
      ++failed;                                                                  \
      fprintf(stderr, "%s:%d: %s returned %s, expected %s\n", __FILE__, __LINE__, \
              #call, tvmd_status_name(got_), tvmd_status_name(expected));        \
    }                                                                            \
  } while (0)

/* tvmd_test.c */
void identity(float m[9]);
TvmdState at_rest(float x, float y, float z);
TvmdReference hover_at(float x, float y, float z);
TvmdOutput empty_output(void);
int diagnostics_nan(const TvmdOutput *o);
/* A recorded tvmd_step. */
TvmdStatus step(TvmdController *c, const TvmdState *s, const TvmdReference *r, TvmdOutput *o);

/* law_test.c */
void test_law(void);

/* stages_test.c */
void test_stages(void);

/* fault_test.c */
void test_fault(void);

#endif
