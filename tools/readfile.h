/* readfile.h - a whole regular file into memory, with a size cap: how the
 * tool reads a map YAML and its image (docs/security.md) and how the bench
 * reads them back. */
#ifndef POLYC_READFILE_H
#define POLYC_READFILE_H

#include <stddef.h>

#define READFILE_TOO_LARGE (-1)   /* more than max bytes */
#define READFILE_NOT_FILE (-2)    /* a device, a FIFO, a socket: not read */

/* Reads the regular file at path, of at most max bytes, into *data
 * (malloc'd, *len bytes; the caller frees it). Returns 0, an errno value
 * (EISDIR for a directory), READFILE_TOO_LARGE or READFILE_NOT_FILE; on
 * failure *data is NULL. A FIFO is opened without waiting for a writer. */
int readfile(const char *path, size_t max, char **data, size_t *len);

#endif /* POLYC_READFILE_H */
