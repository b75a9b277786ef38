/* target.h - the instruction counter of the Cortex-M4F harness
 * (startup.c): the embedded examples, built for qemu's mps2-an386 with
 * -include tools/target/target.h, mark the end of each library call with
 * EMBEDDED_MARK(what, index); the harness prints the instructions between
 * marks when main returns. */
#ifndef TARGET_H
#define TARGET_H

#include <stdint.h>

/* Instructions run since reset (qemu -icount shift=0: SysTick at 25 MHz
 * of virtual time, one instruction a nanosecond, so 40 a tick). */
uint64_t target_instructions(void);

/* Records the instructions since the previous mark as (what, index). */
void target_mark(const char *what, unsigned index);

#define EMBEDDED_MARK(what, index) target_mark(what, index)

#endif
