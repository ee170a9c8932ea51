/* libhdf5's open(2) calls, through the linker's --wrap=open (build.rs): the real open with
 * O_CLOEXEC added, so that no child process started at any moment inherits a descriptor of
 * an HDF5 file with its lock (src/io/h5_open.rs). The mode is read, as open(2) reads it,
 * only where the flags create a file. */
#define _GNU_SOURCE
#include <fcntl.h>
#include <stdarg.h>
#include <sys/types.h>

int __real_open(const char *path, int flags, ...);

int __wrap_open(const char *path, int flags, ...) {
    mode_t mode = 0;
    if (flags & (O_CREAT | O_TMPFILE)) {
        va_list ap;
        va_start(ap, flags);
        mode = va_arg(ap, mode_t);
        va_end(ap);
    }
    return __real_open(path, flags | O_CLOEXEC, mode);
}
