/* startup.c - the Cortex-M4F harness of the embedded examples on qemu's
 * mps2-an386 (make target): vector table, reset (FPU on, .data copied,
 * .bss zeroed), an instruction counter from SysTick, the marks of
 * target.h, a PC sampler (built with -DTARGET_PROFILE) and the exit
 * through semihosting with main's status.
 * Takes: main() of an example, run with -icount shift=0.
 * Gives: the example's own output, then "instructions WHAT INDEX N" lines,
 * "instructions total N", a calibration line and, when profiling, the PC
 * samples in target-pcs.bin (little-endian 32-bit words, PC and LR of
 * each sample). */
#include <stddef.h>
#include <stdint.h>

#include "target.h"

int main(void);
#ifdef TARGET_STDIO
void initialise_monitor_handles(void); /* newlib's rdimon: stdio over semihosting */
#endif

extern uint32_t __data_load[], __data_start[], __data_end[], __bss_start[], __bss_end[];
extern uint32_t __stack_top[];

#define REG(addr) (*(volatile uint32_t *)(addr))
#define SCB_CPACR 0xE000ED88u
#define SYST_CSR 0xE000E010u
#define SYST_RVR 0xE000E014u
#define SYST_CVR 0xE000E018u
#define INSTR_PER_TICK 40u /* 1 GHz of instructions (icount shift 0) / 25 MHz */

#ifdef TARGET_PROFILE
#define RELOAD 99u /* a sample every 100 ticks, 4,000 instructions */
#define MAX_SAMPLES (512u * 1024u)
static uint32_t samples[MAX_SAMPLES];
static volatile uint32_t sample_count;
static uint32_t samples_kept; /* the samples up to the last mark: the library's */
static volatile int sampling;
#else
#define RELOAD 0xFFFFFFu /* the counter's full 24 bits: a wrap per 671 M */
#endif

static volatile uint32_t wraps;

/* ---- semihosting (ARM's "bkpt 0xab" calls) ---- */

static uint32_t semihost(uint32_t op, const void *arg)
{
    register uint32_t r0 __asm__("r0") = op;
    register const void *r1 __asm__("r1") = arg;
    __asm__ volatile("bkpt 0xab" : "+r"(r0) : "r"(r1) : "memory");
    return r0;
}

static void put(const char *s)
{
    semihost(0x04u, s); /* SYS_WRITE0 */
}

static void put_u64(uint64_t v)
{
    char buf[24];
    size_t i = sizeof buf - 1;
    buf[i] = '\0';
    do {
        buf[--i] = (char)('0' + (int)(v % 10u));
        v /= 10u;
    } while (v && i);
    put(buf + i);
}

static void finish(int status)
{
    /* SYS_EXIT: qemu exits 0 for ApplicationExit, 1 for any other reason */
    semihost(0x18u, (const void *)(uintptr_t)(status == 0 ? 0x20026u : 0x20023u));
    for (;;) {
    }
}

/* ---- the counter ---- */

uint64_t target_instructions(void)
{
    uint32_t w, v;
    do { /* a wrap between the two reads: read again */
        w = wraps;
        v = REG(SYST_CVR);
    } while (w != wraps);
    return ((uint64_t)w * (RELOAD + 1u) + (RELOAD - v)) * INSTR_PER_TICK;
}

#define MAX_MARKS 64u
static struct {
    const char *what;
    unsigned index;
    uint64_t instructions;
} marks[MAX_MARKS];
static unsigned mark_count;
static uint64_t last_mark;

void target_mark(const char *what, unsigned index)
{
    uint64_t now = target_instructions();
    if (mark_count < MAX_MARKS) {
        marks[mark_count].what = what;
        marks[mark_count].index = index;
        marks[mark_count].instructions = now - last_mark;
        mark_count++;
    }
#ifdef TARGET_PROFILE
    samples_kept = sample_count;
#endif
    last_mark = target_instructions(); /* the mark's own work not counted */
}

static void report(void)
{
    for (unsigned i = 0; i < mark_count; i++) {
        put("instructions ");
        put(marks[i].what);
        put(" ");
        put_u64(marks[i].index);
        put(" ");
        put_u64(marks[i].instructions);
        put("\n");
    }
    uint64_t sum = 0;
    for (unsigned i = 0; i < mark_count; i++)
        sum += marks[i].instructions;
    put("instructions total ");
    put_u64(sum);
    put("\n");
}

/* A loop of a known length through the counter: the harness's check of
 * its own clock (two instructions an iteration). */
static void calibrate(void)
{
    uint32_t n = 1000000u;
    uint64_t t0 = target_instructions();
    __asm__ volatile("1: subs %0, %0, #1\n\tbne 1b" : "+r"(n) : : "cc");
    uint64_t t1 = target_instructions();
    put("calibration 2000000 ");
    put_u64(t1 - t0);
    put("\n");
}

#ifdef TARGET_PROFILE
static void dump_samples(void)
{
    static const char name[] = "target-pcs.bin";
    uint32_t open_args[3] = {(uint32_t)(uintptr_t)name, 5u /* "wb" */, sizeof name - 1u};
    uint32_t fd = semihost(0x01u, open_args); /* SYS_OPEN */
    if (fd == 0xFFFFFFFFu) {
        put("target: cannot write target-pcs.bin\n");
        return;
    }
    uint32_t write_args[3] = {fd, (uint32_t)(uintptr_t)samples, samples_kept * 4u};
    semihost(0x05u, write_args); /* SYS_WRITE */
    semihost(0x02u, &fd);        /* SYS_CLOSE */
    put("samples ");
    put_u64(samples_kept);
    put("\n");
}
#endif

/* ---- exceptions ---- */

void target_systick_c(const uint32_t *frame);
void target_systick_c(const uint32_t *frame)
{
    wraps++;
#ifdef TARGET_PROFILE
    if (sampling && sample_count + 2u <= MAX_SAMPLES) {
        samples[sample_count++] = frame[6]; /* the stacked PC */
        samples[sample_count++] = frame[5]; /* and LR: the caller of a leaf routine */
    }
#else
    (void)frame;
#endif
}

/* The stacked frame is at the main stack pointer (only MSP is used). */
__attribute__((naked)) static void systick(void)
{
    __asm__ volatile("mov r0, sp\n\tb target_systick_c");
}

static void fault(void)
{
    put("target: fault\n");
    finish(1);
}

void target_reset(void);
void target_reset(void)
{
    REG(SCB_CPACR) |= 0xFu << 20; /* CP10, CP11: full access to the FPU */
    __asm__ volatile("dsb\n\tisb" ::: "memory");
    for (uint32_t *s = __data_load, *d = __data_start; d < __data_end;)
        *d++ = *s++;
    for (uint32_t *d = __bss_start; d < __bss_end;)
        *d++ = 0;
    REG(SYST_RVR) = RELOAD;
    REG(SYST_CVR) = 0;
    REG(SYST_CSR) = 7u; /* enabled, interrupting, the processor's clock */
#ifdef TARGET_STDIO
    initialise_monitor_handles();
#endif
    calibrate();
    last_mark = target_instructions();
#ifdef TARGET_PROFILE
    sampling = 1; /* from main on: not the calibration */
#endif
    int status = main();
    report();
#ifdef TARGET_PROFILE
    dump_samples();
#endif
    if (status != 0) {
        put("target: main returned ");
        put_u64((uint64_t)(unsigned)status);
        put("\n");
    }
    finish(status);
}

/* The vector table: stack, reset, then NMI, HardFault ... SysTick (15). */
__attribute__((section(".vectors"), used)) static void (*const vectors[16])(void) = {
    (void (*)(void))(uintptr_t)__stack_top,
    target_reset,
    fault, fault, fault, fault, fault, 0, 0, 0, 0, /* NMI .. UsageFault, reserved */
    fault, fault, 0,                               /* SVCall, DebugMonitor */
    fault,                                         /* PendSV */
    systick,
};
