/* cli.c - the polyc tool's messages and outputs (cli.h).
 * Takes: messages, the optimiser's iterations, rendered outputs. Gives:
 * "polyc: ..." lines, the progress line on a terminal, and the outputs
 * written all or nothing (outfile.h). */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "cli.h"
#include "outfile.h"
#include "textesc.h"

double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec / 1e6;
}

int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* ---- progress: one line on a terminal ---- */

/* Shown on stderr when it is a terminal (not with --quiet), once a run has
 * taken PROGRESS_AFTER_MS: the stage, and in the optimiser the iteration,
 * vertices and BIC, rewritten in place (carriage return) at each stage and
 * iteration, and blanked before anything else is written to stderr. The
 * stages without a callback (grid, contour) show when they start. */
#define PROGRESS_AFTER_MS 2000.0
#define PROGRESS_EVERY_MS 100.0

static struct progress {
    int on;
    double start_ms, last_ms;
    const char *stage;
    size_t shown;              /* characters of the line now on the terminal */
} prog;

void progress_start(int on, double t_start_ms)
{
    prog.on = on;
    prog.start_ms = prog.last_ms = t_start_ms;
}

int progress_on(void)
{
    return prog.on;
}

void progress_clear(void)
{
    if (!prog.shown)
        return;
    fputc('\r', stderr);
    for (size_t i = 0; i < prog.shown; i++)
        fputc(' ', stderr);
    fputc('\r', stderr);
    fflush(stderr);
    prog.shown = 0;
}

void progress_show(const polyc_iteration *it)
{
    if (!prog.on || !prog.stage)
        return;
    double now = now_ms();
    if (now - prog.start_ms < PROGRESS_AFTER_MS || (it && now - prog.last_ms < PROGRESS_EVERY_MS))
        return;
    prog.last_ms = now;
    char line[160];
    int n = snprintf(line, sizeof line, "polyc: %s", prog.stage);
    if (it && n > 0 && (size_t)n < sizeof line)
        n += snprintf(line + n, sizeof line - (size_t)n, ": iteration %u, %u vertices, BIC %.1f",
                      (unsigned)it->iteration, (unsigned)it->vertices, it->best_bic);
    if (n > 0 && (size_t)n < sizeof line)
        snprintf(line + n, sizeof line - (size_t)n, " (%.1f s)", (now - prog.start_ms) / 1e3);
    size_t len = strlen(line);
    fputc('\r', stderr);
    fputs(line, stderr);
    for (size_t i = len; i < prog.shown; i++)   /* over the rest of a longer line */
        fputc(' ', stderr);
    fflush(stderr);
    prog.shown = len > prog.shown ? len : prog.shown;
}

void progress_stage(const char *stage)
{
    prog.stage = stage;
    progress_show(NULL);
}

/* The message is escaped whole (textesc.h): a file name from the command
 * line cannot send terminal escapes either; input bytes quoted in it are
 * already escaped, and a backslash stays as it is. */
int complain(int code, const char *fmt, ...)
{
    va_list ap, again;
    progress_clear();
    va_start(ap, fmt);
    va_copy(again, ap);
    int n = vsnprintf(NULL, 0, fmt, ap);
    char *msg = n >= 0 ? malloc((size_t)n + 1) : NULL;
    char *shown = NULL;
    if (msg) {
        vsnprintf(msg, (size_t)n + 1, fmt, again);
        shown = textesc_dup(msg);
    }
    va_end(again);
    va_end(ap);
    fprintf(stderr, "polyc: %s\n", shown ? shown : "out of memory (for a message)");
    free(shown);
    free(msg);
    if (code == EXIT_USAGE)
        fputs("try 'polyc --help'\n", stderr);
    return code;
}

const char *input_name(const options *o)
{
    return strcmp(o->input, "-") == 0 ? "<stdin>" : o->input;
}

int membuf_open(membuf *m)
{
    m->data = NULL;
    m->len = 0;
    m->f = open_memstream(&m->data, &m->len);
    return m->f ? 0 : complain(EXIT_INPUT, "out of memory");
}

/* Closes the stream; 0 if everything written to it made it. */
int membuf_close(membuf *m, int write_failed)
{
    int bad = write_failed || ferror(m->f);
    bad = fclose(m->f) != 0 || bad;
    m->f = NULL;
    return bad ? complain(EXIT_INPUT, "out of memory rendering the output") : 0;
}

/* Writes n rendered outputs to their paths (NULL or "-": stdout), all or
 * none where it can (outfile.h): every temporary file is written before
 * anything is renamed or written in place. 0 or EXIT_INPUT with a message. */
int write_outputs(const char *const *paths, const membuf *const *bufs, size_t n)
{
    outfile of[2];
    outfile *ptr[2];
    const char *what = NULL;
    int err = 0;
    size_t made = 0;
    for (; made < n && made < 2 && !err; made++) {
        ptr[made] = &of[made];
        err = outfile_prepare(&of[made], paths[made], bufs[made]->data, bufs[made]->len, &what);
    }
    if (err) {
        for (size_t j = 0; j < made; j++)
            outfile_abort(&of[j]);
        const char *p = paths[made - 1];
        return what ? complain(EXIT_INPUT, "%s: %s (%s)", p, what, strerror(err))
                    : complain(EXIT_INPUT, "%s: %s", p, strerror(err));
    }
    progress_clear();                     /* before stdout, which may be the terminal */
    const outfile *failed = NULL;
    if ((err = outfile_commit_all(ptr, made, &failed)) != 0)
        return failed && failed->kind != OUTFILE_STDOUT
                   ? complain(EXIT_INPUT, "%s: %s", failed->path, strerror(err))
                   : complain(EXIT_INPUT, "writing stdout: %s", strerror(err));
    return 0;
}
