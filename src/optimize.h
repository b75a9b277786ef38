/* optimize.h - the search's entry points (optimize.c): setting the
 * optimiser up, the search loop, and the table of operators that its
 * sequences (an iteration, the polish, an online round) read. The state
 * every file of the search shares is in opt_state.h. */
#ifndef POLYC_OPTIMIZE_H
#define POLYC_OPTIMIZE_H

#include "opt_state.h"

/* optimize.c: one iteration's operators after the noise; `since`: the
 * stamp after which edits are looked at again (0: all), `climb`: the first
 * climb's; returns the stamp taken after the first climb */
uint32_t polyc__operators(polyc__opt *o, uint32_t since, uint32_t climb);
/* opt_setup.c: carves the state from the arena after the trace, scores it */
polyc_status polyc__opt_setup(polyc_ctx *ctx, polyc__opt *o);

/* optimize.c: the search on a set-up optimiser (the batch loop) */
polyc_status polyc__search(polyc__opt *o, polyc_progress_fn progress, void *user);

#endif
