/* outfile.h - how the tool writes a file: all or nothing where it can.
 * Takes: a path (or "-" for stdout) and the bytes to write.
 * Gives: a regular file (or a new name) replaced atomically, keeping its
 * mode and owner: the bytes go to an unnamed file in its folder (O_TMPFILE;
 * else a named temporary file), linked in under the name when complete; a
 * symlink's target replaced the same way, a symlink in a sticky,
 * world-writable folder followed only by the kernel's fs.protected_symlinks
 * rule; a device, FIFO or stdout written in place. No temporary file
 * survives an error, an exit or a catchable signal. */
#ifndef POLYC_OUTFILE_H
#define POLYC_OUTFILE_H

#include <stddef.h>

enum outfile_kind {
    OUTFILE_STDOUT,            /* "-" */
    OUTFILE_REPLACE,           /* a regular file or a new name: temp + rename */
    OUTFILE_IN_PLACE           /* a device, a FIFO: opened and written; /dev/stdout,
                                  /dev/fd/N: that descriptor written */
};

typedef struct outfile {
    const char *path;          /* as given (messages) */
    char *target;              /* the file written: path with its symlinks resolved */
    const char *base;          /* its last component (in target) */
    int dir;                   /* its folder, open (the *at calls), or -1 */
    enum outfile_kind kind;
    const char *data;          /* not owned */
    size_t len;
    int fresh;                 /* OUTFILE_REPLACE: no file had the name when prepared */
    int tmpfd;                 /* OUTFILE_REPLACE: the written unnamed file, or -1 */
    char tmp[16];              /* a named temporary file in dir while it exists, or "" */
    int slot;                  /* its place in the signal handlers' list, or -1 */
    int fd;                    /* OUTFILE_IN_PLACE: this process's descriptor that the
                                  name stands for (/dev/stdout: 1), written as is; or -1 */
} outfile;

/* Catches every catchable signal whose default ends the process (SIGINT,
 * SIGTERM, SIGHUP, SIGQUIT, SIGUSR1, SIGALRM, the real-time signals, ...;
 * not one ignored or handled when the program started) to remove the
 * temporary files, then dies of the signal; ignores SIGPIPE and SIGXFSZ, so
 * that writing to a closed pipe or past `ulimit -f` is an error that is
 * reported. */
void outfile_signals(void);

/* Checks a path given as an output before any work: NULL if it is usable,
 * else why not ("is empty", "names a directory", a symlink refused by the
 * fs.protected_symlinks rule, a folder that is missing or not writable),
 * a static string. */
const char *outfile_check(const char *path);

/* 1 if a and b (outputs, "-" for stdout) are the same file: the same name,
 * the same resolved target, or the same inode. A character device such as
 * /dev/null may be named twice. */
int outfile_same(const char *a, const char *b);

/* 1 if the output out ("-": stdout) is the input in ("-": stdin): the same
 * regular file (device and inode, through links). */
int outfile_is_input(const char *out, const char *in);

/* Resolves path and, for a file to replace, writes data to a synced
 * unnamed (or temporary) file in the target's folder. data must live until
 * outfile_commit. 0, or an errno value (*what says what failed, or NULL for
 * the error alone). */
int outfile_prepare(outfile *o, const char *path, const char *data, size_t len, const char **what);

/* Writes stdout or the file in place (kind != OUTFILE_REPLACE), or gives
 * the written file the target's name. 0 or an errno value; the temporary
 * file is gone either way. */
int outfile_commit(outfile *o);

/* Removes what outfile_prepare left and frees o's resources; safe to call
 * twice and after outfile_commit. */
void outfile_abort(outfile *o);

/* Commits n prepared outputs, both or neither where it can: first those
 * written in place (stdout, devices), which can fail half-way, then the
 * renames, in their order. On failure *failed is the one that failed and
 * every temporary file is removed. 0 or an errno value. */
int outfile_commit_all(outfile *const *outs, size_t n, const outfile **failed);

#endif /* POLYC_OUTFILE_H */
