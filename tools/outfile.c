/* outfile.c - how the tool writes a file (outfile.h).
 * Takes: a path and bytes rendered in memory.
 * Gives: the bytes in the file (atomically for a regular file), stdout or a
 * device; temporary files listed for the signal handlers to remove. */
#define _XOPEN_SOURCE 700       /* realpath */
#include "outfile.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#define OUTFILE_MAX_TEMPS 8
#define OUTFILE_MAX_LINKS 40           /* as the kernel's ELOOP limit */
#define OUTFILE_TEMP_NAME ".polyc-XXXXXX"

/* ---- the temporary files, for the signal handlers ---- */

static char *volatile temps[OUTFILE_MAX_TEMPS];
static const int caught[] = {SIGINT, SIGTERM, SIGHUP};

static void on_signal(int sig)
{
    for (int i = 0; i < OUTFILE_MAX_TEMPS; i++) {
        char *p = temps[i];
        if (p)
            unlink(p);                 /* async-signal-safe */
    }
    signal(sig, SIG_DFL);
    raise(sig);                        /* delivered when the handler returns */
}

void outfile_signals(void)
{
    struct sigaction sa, old;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    for (size_t i = 0; i < sizeof caught / sizeof caught[0]; i++)
        sigaddset(&sa.sa_mask, caught[i]);
    for (size_t i = 0; i < sizeof caught / sizeof caught[0]; i++)
        if (sigaction(caught[i], NULL, &old) == 0 && old.sa_handler != SIG_IGN)
            sigaction(caught[i], &sa, NULL);   /* (nohup's SIGHUP stays ignored) */
    signal(SIGPIPE, SIG_IGN);          /* a closed pipe: EPIPE, reported */
}

/* The caught signals held back while the list changes. */
static void hold(int on, sigset_t *saved)
{
    if (on) {
        sigset_t set;
        sigemptyset(&set);
        for (size_t i = 0; i < sizeof caught / sizeof caught[0]; i++)
            sigaddset(&set, caught[i]);
        sigprocmask(SIG_BLOCK, &set, saved);
    } else {
        sigprocmask(SIG_SETMASK, saved, NULL);
    }
}

static void forget(outfile *o)
{
    if (o->slot >= 0) {
        sigset_t saved;
        hold(1, &saved);
        temps[o->slot] = NULL;
        hold(0, &saved);
        o->slot = -1;
    }
}

/* ---- names ---- */

/* A name the kernel makes up (/proc/self/fd/N, /dev/stdout): followed by
 * open(), not by reading links. */
static int is_magic(const char *p)
{
    return strncmp(p, "/proc/", 6) == 0 || strncmp(p, "/dev/fd/", 8) == 0 ||
           strcmp(p, "/dev/stdin") == 0 || strcmp(p, "/dev/stdout") == 0 ||
           strcmp(p, "/dev/stderr") == 0;
}

/* The descriptor of this process that a magic name stands for
 * (/dev/stdout, /dev/fd/N, /proc/self/fd/N), or -1. */
static int own_fd(const char *p)
{
    if (strcmp(p, "/dev/stdout") == 0)
        return STDOUT_FILENO;
    if (strcmp(p, "/dev/stderr") == 0)
        return STDERR_FILENO;
    const char *n = strncmp(p, "/dev/fd/", 8) == 0         ? p + 8
                    : strncmp(p, "/proc/self/fd/", 14) == 0 ? p + 14
                                                            : NULL;
    if (!n || *n < '0' || *n > '9')
        return -1;
    char *end;
    long fd = strtol(n, &end, 10);
    return *end || fd > INT_MAX ? -1 : (int)fd;
}

/* The folder part of p ("" or up to its last '/'), with s appended. */
static char *in_dir_of(const char *p, const char *s)
{
    const char *slash = strrchr(p, '/');
    size_t d = slash ? (size_t)(slash - p) + 1 : 0, n = strlen(s);
    char *out = malloc(d + n + 1);
    if (out) {
        memcpy(out, p, d);
        memcpy(out + d, s, n + 1);
    }
    return out;
}

/* path with every symlink of its last component followed (not those of its
 * folders: the rename stays in the link target's folder). NULL and *err. */
static char *resolve(const char *path, int *err)
{
    char *cur = malloc(strlen(path) + 1);
    if (!cur) {
        *err = ENOMEM;
        return NULL;
    }
    strcpy(cur, path);
    for (int hop = 0; hop <= OUTFILE_MAX_LINKS; hop++) {
        struct stat st;
        if (is_magic(cur) || lstat(cur, &st) != 0 || !S_ISLNK(st.st_mode))
            return cur;
        char link[PATH_MAX];
        ssize_t n = readlink(cur, link, sizeof link - 1);
        if (n < 0) {
            *err = errno;
            free(cur);
            return NULL;
        }
        link[n] = '\0';
        char *next = link[0] == '/' ? in_dir_of("", link) : in_dir_of(cur, link);
        free(cur);
        if (!(cur = next)) {
            *err = ENOMEM;
            return NULL;
        }
    }
    free(cur);
    *err = ELOOP;
    return NULL;
}

const char *outfile_check(const char *path)
{
    struct stat st;
    if (!path || strcmp(path, "-") == 0)
        return NULL;
    if (!*path)
        return "is empty";
    if (path[strlen(path) - 1] == '/' || (stat(path, &st) == 0 && S_ISDIR(st.st_mode)))
        return "names a directory";
    return NULL;
}

/* The target's folder made absolute, and its name: one spelling per file. */
static char *canonical(const char *path)
{
    int err;
    char *t = resolve(path, &err), *out = NULL;
    if (!t)
        return NULL;
    char *dir = in_dir_of(t, ".");
    char real[PATH_MAX];
    const char *slash = strrchr(t, '/');
    const char *base = slash ? slash + 1 : t;
    if (dir && realpath(dir, real) && (out = malloc(strlen(real) + strlen(base) + 2)))
        sprintf(out, "%s/%s", real, base);
    free(dir);
    free(t);
    return out;
}

int outfile_same(const char *a, const char *b)
{
    int sa = !a || strcmp(a, "-") == 0, sb = !b || strcmp(b, "-") == 0;
    if (sa && sb)
        return 1;
    struct stat x, y;
    int hx = sa ? fstat(STDOUT_FILENO, &x) == 0 : stat(a, &x) == 0;
    int hy = sb ? fstat(STDOUT_FILENO, &y) == 0 : stat(b, &y) == 0;
    if (hx && hy)                      /* both exist: the inode decides */
        return x.st_dev == y.st_dev && x.st_ino == y.st_ino && !S_ISCHR(x.st_mode);
    if (hx || hy || sa || sb)
        return 0;
    char *ca = canonical(a), *cb = canonical(b);
    int same = ca && cb ? strcmp(ca, cb) == 0 : strcmp(a, b) == 0;
    free(ca);
    free(cb);
    return same;
}

/* ---- writing ---- */

static int write_all(int fd, const char *data, size_t len)
{
    for (size_t done = 0; done < len;) {
        ssize_t w = write(fd, data + done, len - done);
        if (w < 0 && errno != EINTR)
            return errno;
        if (w > 0)
            done += (size_t)w;
    }
    return 0;
}

int outfile_prepare(outfile *o, const char *path, const char *data, size_t len, const char **what)
{
    memset(o, 0, sizeof *o);
    o->path = path;
    o->data = data;
    o->len = len;
    o->slot = -1;
    o->fd = -1;
    *what = NULL;
    if (!path || strcmp(path, "-") == 0) {
        o->kind = OUTFILE_STDOUT;
        return 0;
    }
    int err = 0;
    if (!(o->target = resolve(path, &err)))
        return err;
    struct stat st;
    int exists = stat(o->target, &st) == 0;
    if (exists && S_ISDIR(st.st_mode))
        return EISDIR;
    if (is_magic(o->target) || (exists && !S_ISREG(st.st_mode))) {
        o->kind = OUTFILE_IN_PLACE;
        o->fd = own_fd(o->target);     /* written as is: a shell's >> stays an append */
        return 0;
    }
    o->kind = OUTFILE_REPLACE;
    if (!(o->tmp = in_dir_of(o->target, OUTFILE_TEMP_NAME)))
        return ENOMEM;
    sigset_t saved;
    hold(1, &saved);                   /* listed before a signal can see it */
    int fd = mkstemp(o->tmp);
    err = fd < 0 ? errno : 0;
    for (int i = 0; fd >= 0 && i < OUTFILE_MAX_TEMPS && o->slot < 0; i++)
        if (!temps[i]) {
            temps[i] = o->tmp;
            o->slot = i;
        }
    if (fd >= 0 && o->slot < 0) {
        unlink(o->tmp);
        close(fd);
        fd = -1;
        err = EMFILE;
    }
    hold(0, &saved);
    if (fd < 0) {
        free(o->tmp);
        o->tmp = NULL;
        *what = "cannot create a temporary file";
        return err;
    }
    if (exists) {                      /* the file's owner and mode, as far as allowed */
        if (fchown(fd, st.st_uid, st.st_gid) != 0) {
            /* not ours to give away: the new file is the writer's */
        }
        err = fchmod(fd, st.st_mode & 07777) ? errno : 0;
    } else {
        mode_t mask = umask(0);        /* mkstemp makes 0600; give the usual mode */
        umask(mask);
        err = fchmod(fd, 0666 & ~mask) ? errno : 0;
    }
    if (!err)
        err = write_all(fd, data, len);
    if (!err && fsync(fd) != 0)
        err = errno;
    if (close(fd) != 0 && !err)
        err = errno;
    if (err)
        outfile_abort(o);
    return err;
}

int outfile_commit(outfile *o)
{
    int err = 0;
    if (o->kind == OUTFILE_STDOUT) {
        errno = 0;
        if (fwrite(o->data, 1, o->len, stdout) != o->len || fflush(stdout) != 0)
            err = errno ? errno : EIO;
    } else if (o->kind == OUTFILE_IN_PLACE && o->fd >= 0) {
        if (o->fd == STDOUT_FILENO && fflush(stdout) != 0)
            err = errno;
        if (!err)
            err = write_all(o->fd, o->data, o->len);
    } else if (o->kind == OUTFILE_IN_PLACE) {
        struct stat st;
        int trunc = stat(o->target, &st) == 0 && S_ISREG(st.st_mode) ? O_TRUNC : 0;
        int fd = open(o->target, O_WRONLY | O_NOCTTY | trunc);
        if (fd < 0)
            return errno;
        err = write_all(fd, o->data, o->len);
        if (close(fd) != 0 && !err)
            err = errno;
    } else if (o->tmp) {
        err = rename(o->tmp, o->target) != 0 ? errno : 0;
        if (!err) {
            forget(o);
            free(o->tmp);
            o->tmp = NULL;
        }
    }
    outfile_abort(o);
    return err;
}

void outfile_abort(outfile *o)
{
    if (o->tmp) {
        unlink(o->tmp);
        forget(o);
        free(o->tmp);
        o->tmp = NULL;
    }
    free(o->target);
    o->target = NULL;
}

int outfile_commit_all(outfile *const *outs, size_t n, const outfile **failed)
{
    int err = 0;
    *failed = NULL;
    for (int pass = 0; pass < 2 && !err; pass++)
        for (size_t i = 0; i < n && !err; i++)
            if ((outs[i]->kind == OUTFILE_REPLACE) == pass && (err = outfile_commit(outs[i])))
                *failed = outs[i];
    for (size_t i = 0; i < n; i++)
        outfile_abort(outs[i]);
    return err;
}
