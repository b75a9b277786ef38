/* outfile.c - how the tool writes a file (outfile.h).
 * Takes: a path and bytes rendered in memory.
 * Gives: the bytes in the file (atomically for a regular file), stdout or a
 * device; temporary files listed for the signal handlers to remove. */
#define _GNU_SOURCE             /* O_TMPFILE, O_PATH, AT_EMPTY_PATH; realpath */
#include "outfile.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#define OUTFILE_MAX_TEMPS 8
#define OUTFILE_MAX_LINKS 40           /* as the kernel's ELOOP limit */
#define OUTFILE_TEMP_NAME ".polyc-"    /* and 6 letters or digits */
#define OUTFILE_REFUSED (-1)           /* locate: a symlink not to follow */
#define OUTFILE_RULE "is a symlink in a sticky, world-writable folder that neither you nor the" \
                     " folder's owner owns: not followed (the kernel's fs.protected_symlinks rule)"
#ifdef NSIG
#define OUTFILE_NSIG NSIG              /* signals are 1 .. NSIG - 1 */
#else
#define OUTFILE_NSIG 65
#endif
#ifdef O_PATH
#define OUTFILE_DIR_FLAGS (O_PATH | O_DIRECTORY | O_CLOEXEC)
#else
#define OUTFILE_DIR_FLAGS (O_RDONLY | O_DIRECTORY | O_CLOEXEC)
#endif

/* ---- the temporary files, for the signal handlers ---- */

/* A named temporary file: its name in its folder's descriptor. */
static char *volatile temps[OUTFILE_MAX_TEMPS];
static volatile sig_atomic_t temp_dirs[OUTFILE_MAX_TEMPS];
static sigset_t caught;                /* the signals on_signal handles */

static void on_signal(int sig)
{
    for (int i = 0; i < OUTFILE_MAX_TEMPS; i++) {
        char *p = temps[i];
        if (p)
            unlinkat((int)temp_dirs[i], p, 0);   /* async-signal-safe */
    }
    signal(sig, SIG_DFL);
    raise(sig);                        /* delivered when the handler returns */
}

/* Every signal whose default action ends the process, but SIGKILL and
 * SIGSTOP's kind (not catchable) and SIGPIPE and SIGXFSZ (ignored). */
static int ends_process(int sig)
{
    static const int term[] = {
        SIGHUP, SIGINT, SIGQUIT, SIGILL, SIGTRAP, SIGABRT, SIGBUS, SIGFPE, SIGUSR1, SIGSEGV,
        SIGUSR2, SIGALRM, SIGTERM, SIGXCPU, SIGVTALRM, SIGPROF, SIGSYS,
#ifdef SIGSTKFLT
        SIGSTKFLT,
#endif
#ifdef SIGPOLL
        SIGPOLL,
#endif
#ifdef SIGPWR
        SIGPWR,
#endif
    };
    for (size_t i = 0; i < sizeof term / sizeof term[0]; i++)
        if (term[i] == sig)
            return 1;
#ifdef SIGRTMIN
    if (sig >= SIGRTMIN && sig <= SIGRTMAX)
        return 1;
#endif
    return 0;
}

void outfile_signals(void)
{
    struct sigaction sa, old;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigemptyset(&caught);
    for (int sig = 1; sig < OUTFILE_NSIG; sig++)
        if (ends_process(sig))
            sigaddset(&caught, sig);
    sa.sa_mask = caught;
    for (int sig = 1; sig < OUTFILE_NSIG; sig++) {
        if (!ends_process(sig))
            continue;
        /* one ignored (nohup's SIGHUP) or handled (a sanitizer's SIGSEGV)
         * when polyc started stays so */
        if (sigaction(sig, NULL, &old) == 0 && !(old.sa_flags & SA_SIGINFO) &&
            old.sa_handler == SIG_DFL)
            sigaction(sig, &sa, NULL);
        else
            sigdelset(&caught, sig);
    }
    signal(SIGPIPE, SIG_IGN);          /* a closed pipe: EPIPE, reported */
    signal(SIGXFSZ, SIG_IGN);          /* past ulimit -f: EFBIG, reported */
}

/* The caught signals held back while the list changes. */
static void hold(int on, sigset_t *saved)
{
    if (on)
        sigprocmask(SIG_BLOCK, &caught, saved);
    else
        sigprocmask(SIG_SETMASK, saved, NULL);
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

/* Makes a name .polyc-XXXXXX in o->dir with make(o), which returns 0, or
 * an errno value (EEXIST: try another name); lists it for the handlers.
 * 0 or an errno value. */
static int new_temp(outfile *o, int (*make)(outfile *o, int *fd), int *fd)
{
    static const char letters[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789";
    static unsigned long seq;
    unsigned long x = (unsigned long)getpid() * 2654435761ul ^ (unsigned long)time(NULL);
    sigset_t saved;
    int err = EMFILE, slot = -1;
    hold(1, &saved);                   /* listed before a signal can see it */
    for (int i = 0; i < OUTFILE_MAX_TEMPS && slot < 0; i++)
        if (!temps[i])
            slot = i;
    for (int tries = 0; slot >= 0 && tries < 100; tries++) {
        unsigned long v = x + 7919ul * ++seq;
        memcpy(o->tmp, OUTFILE_TEMP_NAME, sizeof OUTFILE_TEMP_NAME - 1);
        for (size_t k = 0; k < 6; k++, v /= 62)
            o->tmp[sizeof OUTFILE_TEMP_NAME - 1 + k] = letters[v % 62];
        o->tmp[sizeof OUTFILE_TEMP_NAME + 5] = '\0';
        if ((err = make(o, fd)) != EEXIST)
            break;
    }
    if (!err) {
        temp_dirs[slot] = o->dir;
        temps[slot] = o->tmp;
        o->slot = slot;
    } else {
        o->tmp[0] = '\0';
    }
    hold(0, &saved);
    return err;
}

/* new_temp's makers: an empty file, and the unnamed file's link. */
static int create_temp(outfile *o, int *fd)
{
    *fd = openat(o->dir, o->tmp, O_CREAT | O_EXCL | O_WRONLY | O_NOFOLLOW | O_CLOEXEC, 0600);
    return *fd < 0 ? errno : 0;
}

/* Gives the unnamed file o->tmpfd the name `name` in o->dir; 0 or an
 * errno value (EEXIST: the name is taken). */
static int link_unnamed(const outfile *o, const char *name)
{
    char proc[48];
    snprintf(proc, sizeof proc, "/proc/self/fd/%d", o->tmpfd);
    if (linkat(AT_FDCWD, proc, o->dir, name, AT_SYMLINK_FOLLOW) == 0)
        return 0;
    int err = errno;
#ifdef AT_EMPTY_PATH
    if (err == ENOENT && linkat(o->tmpfd, "", o->dir, name, AT_EMPTY_PATH) == 0)
        return 0;                      /* no /proc: allowed with CAP_DAC_READ_SEARCH */
#endif
    return err;
}

static int link_temp(outfile *o, int *fd)
{
    (void)fd;
    return link_unnamed(o, o->tmp);
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

static const char *base_of(const char *p)
{
    const char *slash = strrchr(p, '/');
    return slash ? slash + 1 : p;
}

/* Follows path's last component through its symlinks, each looked at and
 * read in its folder opened as a descriptor, by the kernel's
 * fs.protected_symlinks rule: in a sticky, world-writable folder, a link is
 * followed only if the caller or the folder's owner owns it (the folders on
 * the way are the kernel's to follow). *target: the name at the end
 * (malloc'd); *dir: its folder, open, or -1 for a name the kernel makes up
 * (is_magic). 0, OUTFILE_REFUSED or an errno value (*folder set if it is
 * the folder's: it could not be opened). */
static int locate(const char *path, char **target, int *dir, int *folder)
{
    *target = NULL;
    *dir = -1;
    *folder = 0;
    char *cur = in_dir_of("", path);
    if (!cur)
        return ENOMEM;
    for (int hop = 0; hop <= OUTFILE_MAX_LINKS; hop++) {
        if (is_magic(cur)) {
            *target = cur;
            return 0;
        }
        char *d = in_dir_of(cur, ".");
        int fd = d ? open(d, OUTFILE_DIR_FLAGS) : -1;
        int err = !d ? ENOMEM : fd < 0 ? errno : 0;
        free(d);
        if (err) {
            *folder = err != ENOMEM;
            free(cur);
            return err;
        }
        const char *base = base_of(cur);
        struct stat ls, ds;
        if (fstatat(fd, base, &ls, AT_SYMLINK_NOFOLLOW) != 0 || !S_ISLNK(ls.st_mode)) {
            *target = cur;
            *dir = fd;
            return 0;
        }
        char link[PATH_MAX];
        ssize_t n = -1;
        if (fstat(fd, &ds) != 0)
            err = errno;
        else if ((ds.st_mode & S_ISVTX) && (ds.st_mode & S_IWOTH) && ls.st_uid != geteuid() &&
                 ls.st_uid != ds.st_uid)
            err = OUTFILE_REFUSED;
        else if ((n = readlinkat(fd, base, link, sizeof link - 1)) < 0)
            err = errno;
        close(fd);
        char *next = NULL;
        if (!err) {
            link[n] = '\0';
            next = link[0] == '/' ? in_dir_of("", link) : in_dir_of(cur, link);
            err = next ? 0 : ENOMEM;
        }
        free(cur);
        if (err)
            return err;
        cur = next;
    }
    free(cur);
    return ELOOP;
}

const char *outfile_check(const char *path)
{
    if (!path || strcmp(path, "-") == 0)
        return NULL;
    if (!*path)
        return "is empty";
    if (path[strlen(path) - 1] == '/')
        return "names a directory";
    char *t;
    int dir, folder;
    int err = locate(path, &t, &dir, &folder);
    const char *why = NULL;
    struct stat st;
    if (err == OUTFILE_REFUSED)
        why = OUTFILE_RULE;
    else if (err == ENOMEM)
        why = "cannot be checked (out of memory)";
    else if (err == ELOOP)
        why = "is a loop or a chain of too many symlinks";
    else if (err && folder)
        why = err == ENOENT    ? "is in a folder that does not exist"
              : err == ENOTDIR ? "is in a folder that is not a folder"
              : err == EACCES  ? "is in a folder that you may not enter"
                               : "is in a folder that cannot be opened";
    else if (err)
        why = "is a symlink that cannot be read";
    else if (dir >= 0) {
        int exists = fstatat(dir, base_of(t), &st, AT_SYMLINK_NOFOLLOW) == 0;
        if (exists && S_ISDIR(st.st_mode))
            why = "names a directory";
        else if ((!exists || S_ISREG(st.st_mode)) &&
                 faccessat(dir, ".", W_OK | X_OK, AT_EACCESS) != 0)
            why = errno == EROFS ? "is on a read-only file system"
                                 : "is in a folder that you may not write";
    }
    if (dir >= 0)
        close(dir);
    free(t);
    return why;
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

int outfile_is_input(const char *out, const char *in)
{
    struct stat x, y;
    int so = !out || strcmp(out, "-") == 0, si = !in || strcmp(in, "-") == 0;
    if ((so ? fstat(STDOUT_FILENO, &x) : stat(out, &x)) != 0 ||
        (si ? fstat(STDIN_FILENO, &y) : stat(in, &y)) != 0)
        return 0;
    return S_ISREG(x.st_mode) && x.st_dev == y.st_dev && x.st_ino == y.st_ino;
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
    o->dir = -1;
    o->tmpfd = -1;
    *what = NULL;
    if (!path || strcmp(path, "-") == 0) {
        o->kind = OUTFILE_STDOUT;
        return 0;
    }
    int folder, err = locate(path, &o->target, &o->dir, &folder);
    if (err == OUTFILE_REFUSED) {
        *what = OUTFILE_RULE;
        return EACCES;
    }
    if (err) {
        *what = folder ? "cannot open its folder" : NULL;
        return err;
    }
    o->base = base_of(o->target);
    if (o->dir < 0) {                  /* /dev/stdout, /proc/self/fd/N, ... */
        o->kind = OUTFILE_IN_PLACE;
        o->fd = own_fd(o->target);     /* written as is: a shell's >> stays an append */
        return 0;
    }
    struct stat st;
    int exists = fstatat(o->dir, o->base, &st, AT_SYMLINK_NOFOLLOW) == 0;
    if (exists && S_ISDIR(st.st_mode))
        return EISDIR;
    if (exists && !S_ISREG(st.st_mode)) {
        o->kind = OUTFILE_IN_PLACE;
        return 0;
    }
    o->kind = OUTFILE_REPLACE;
    o->fresh = !exists;
    int fd = -1;
#ifdef O_TMPFILE
    fd = openat(o->dir, ".", O_TMPFILE | O_WRONLY | O_CLOEXEC, 0666);   /* less the umask */
    o->tmpfd = fd;
#endif
    if (fd < 0 && (err = new_temp(o, create_temp, &fd)) != 0) {
        *what = "cannot create a file in its folder";
        outfile_abort(o);
        return err;
    }
    if (exists) {                      /* the file's owner and mode, as far as allowed */
        if (fchown(fd, st.st_uid, st.st_gid) != 0) {
            /* not ours to give away: the new file is the writer's */
        }
        err = fchmod(fd, st.st_mode & 07777) ? errno : 0;
    } else if (o->tmpfd < 0) {
        mode_t mask = umask(0);        /* made 0600; give the usual mode */
        umask(mask);
        err = fchmod(fd, 0666 & ~mask) ? errno : 0;
    }
    if (!err)
        err = write_all(fd, data, len);
    if (!err && fsync(fd) != 0)
        err = errno;
    if (o->tmpfd < 0 && close(fd) != 0 && !err)
        err = errno;
    if (err)
        outfile_abort(o);
    return err;
}

/* The written file under the target's name: an unnamed file linked in
 * (a new name) or linked to a temporary name first, then renamed over it. */
static int give_name(outfile *o)
{
    int err = 0, unused;
    if (o->tmpfd >= 0 && o->fresh && (err = link_unnamed(o, o->base)) != EEXIST)
        return err;                    /* (EEXIST: made meanwhile, so replaced) */
    if (o->tmpfd >= 0 && (err = new_temp(o, link_temp, &unused)) != 0)
        return err;
    if (renameat(o->dir, o->tmp, o->dir, o->base) != 0)
        return errno;
    forget(o);
    o->tmp[0] = '\0';
    return 0;
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
        int flags = O_WRONLY | O_NOCTTY | O_CLOEXEC, fd;
        if (o->dir >= 0) {             /* the file looked at, not a link put there since */
            if (fstatat(o->dir, o->base, &st, AT_SYMLINK_NOFOLLOW) == 0 && S_ISREG(st.st_mode))
                flags |= O_TRUNC;
            fd = openat(o->dir, o->base, flags | O_NOFOLLOW);
        } else {
            if (stat(o->target, &st) == 0 && S_ISREG(st.st_mode))
                flags |= O_TRUNC;
            fd = open(o->target, flags);
        }
        if (fd < 0)
            return errno;
        err = write_all(fd, o->data, o->len);
        if (close(fd) != 0 && !err)
            err = errno;
    } else if (o->tmpfd >= 0 || o->tmp[0]) {
        err = give_name(o);
    }
    outfile_abort(o);
    return err;
}

void outfile_abort(outfile *o)
{
    if (o->tmp[0]) {
        unlinkat(o->dir, o->tmp, 0);
        forget(o);
        o->tmp[0] = '\0';
    }
    if (o->tmpfd >= 0)
        close(o->tmpfd);               /* an unnamed file goes with its last descriptor */
    o->tmpfd = -1;
    if (o->dir >= 0)
        close(o->dir);
    o->dir = -1;
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
