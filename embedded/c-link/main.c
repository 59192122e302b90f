/* tvmd's C interface in a bare-metal C program built with arm-none-eabi-gcc for the
 * Cortex-M4F (see scripts/ffi.sh for the flags, link.ld for the memory map): start-up code,
 * then the default controller hovers the paper's team for 50 periods, and the program exits
 * through semihosting with success only if every step returned TVMD_OK with finite, admissible
 * commands. No C library: tvmd needs none (the Rust staticlib brings memcpy and memset). */
#include <stdint.h>

#include "tvmd.h"

/* Semihosting (ARM DUI 0471): SYS_WRITE0 prints a string, SYS_EXIT ends the program; QEMU
 * exits with 0 for ADP_Stopped_ApplicationExit and 1 for any other reason. */
static uint32_t semihost(uint32_t op, const void *arg) {
  register uint32_t r0 __asm__("r0") = op;
  register const void *r1 __asm__("r1") = arg;
  __asm__ volatile("bkpt 0xab" : "+r"(r0) : "r"(r1) : "memory");
  return r0;
}

static void say(const char *text) { (void)semihost(0x04u, text); }

static void finish(int ok) {
  say(ok ? "c-link: ok\n" : "c-link: FAILED\n");
  (void)semihost(0x18u, (const void *)(uintptr_t)(ok ? 0x20026u : 0x20023u));
  for (;;) {
  }
}

static TvmdController controller; /* in .bss: zeroed by the start-up code */

static int hover(void) {
  TvmdConfig config = {0};
  TvmdState state = {0};
  TvmdReference reference = {0};
  TvmdOutput out = {0};
  uint32_t k, i;
  config.size = sizeof config;
  if (tvmd_config_default(&config) != TVMD_OK) return 0;
  if (tvmd_create(&controller, sizeof controller, &config) != TVMD_OK) return 0;
  if (tvmd_check(&controller) != TVMD_OK) return 0;
  state.size = sizeof state;
  reference.size = sizeof reference;
  out.size = sizeof out;
  for (i = 0; i < 9; ++i) {
    state.attitude[i] = (i % 4 == 0) ? 1.0f : 0.0f;
    reference.attitude[i] = state.attitude[i];
  }
  state.position[2] = 1.45f; /* 5 cm below the reference */
  reference.position[2] = 1.5f;
  for (k = 0; k < 50; ++k) {
    float lift = 0.0f;
    if (tvmd_step(&controller, &state, &reference, &out) != TVMD_OK) return 0;
    if (out.agent_count != 4) return 0;
    for (i = 0; i < out.agent_count; ++i) {
      const TvmdAgentCommand *c = &out.commands[i];
      /* Finite (NaN fails every comparison) and inside the paper's thrust range. */
      if (!(c->thrust >= 0.0f && c->thrust <= 2.0f * 0.7f * 9.81f + 1e-3f)) return 0;
      lift += c->thrust;
    }
    /* The team (2.8 kg) is held up and pushed toward the reference: more than its weight. */
    if (!(lift > 2.8f * 9.81f)) return 0;
  }
  return 1;
}

extern uint32_t _data_start, _data_end, _data_load, _bss_start, _bss_end, _stack_top;

void reset_handler(void) {
  uint32_t *dst = &_data_start;
  const uint32_t *src = &_data_load;
  while (dst < &_data_end) *dst++ = *src++;
  for (dst = &_bss_start; dst < &_bss_end;) *dst++ = 0;
  /* Full access to the FPU (CP10, CP11) before any floating-point instruction. */
  *(volatile uint32_t *)0xE000ED88u |= 0xFu << 20;
  __asm__ volatile("dsb\n\tisb" ::: "memory");
  finish(hover());
}

static void fault_handler(void) { finish(0); }

/* Initial stack pointer, reset, NMI, HardFault, MemManage, BusFault, UsageFault. */
__attribute__((section(".isr_vector"), used)) static void (*const vectors[7])(void) = {
    (void (*)(void))(uintptr_t)&_stack_top, reset_handler, fault_handler, fault_handler,
    fault_handler, fault_handler, fault_handler,
};
