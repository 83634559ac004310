// An LD_PRELOAD shim that makes the disk under one directory full (ENOSPC) or failing (EIO) on demand,
// without privileges: libfiu's fiu-run fails every write, sockets included, and a size-limited tmpfs
// needs CAP_SYS_ADMIN. Only what would store data under COLORLAB_FAULT_DIR fails: write/pwrite/writev on
// descriptors of files there, their syncs and size changes, and (ENOSPC only) mkdir, which needs a block.
// Creating, opening and renaming files still work, as on a real full disk, whose free inodes outlast its
// blocks: a writer gets as far as a half-written file, which is what the tests must never see served.
// Reads, unlinks (they free space) and every other descriptor pass.
//
// COLORLAB_FAULT_DIR      the directory (the daemon's state directory); it must exist when the process
//                         first writes, for the shim resolves it once
// COLORLAB_FAULT_CONTROL  a file the test rewrites (atomically, by rename) to switch faults at run time:
//                         absent or "off": none; "ENOSPC" or "EIO", optionally followed by a path relative
//                         to the directory ("ENOSPC blobs") to fail only what lies under it.
//                         "HOLD" (optionally with a path, as above): nothing fails, but an fsync or fdatasync
//                         of a file there waits — with "<control>.held" created — until the control file
//                         says something else (or 120 s pass): a commit held in its sync, for as long as a
//                         test needs to look at what the process still does meanwhile (issue 27).
// The control file is stat()ed on each intercepted call and re-read only when it changed, so a test's
// switch takes effect at the next write without the shim costing a read per write.
#define _GNU_SOURCE
#include <dlfcn.h>
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <sys/types.h>
#include <sys/uio.h>
#include <time.h>
#include <unistd.h>

static pthread_once_t g_once = PTHREAD_ONCE_INIT;
static pthread_mutex_t g_mutex = PTHREAD_MUTEX_INITIALIZER;
static char g_dir[PATH_MAX];      // the fault directory, canonical; empty: the shim does nothing
static char g_control[PATH_MAX];  // the control file's path
static struct stat g_seen;        // the control file as last read
static int g_seen_valid;
static int g_errno;               // 0: no fault
static int g_hold;                // HOLD: syncs in scope wait
static char g_scope[PATH_MAX * 2];  // the failing subtree (g_dir or below)

// Set by the shim's constructor. A sanitizer's runtime starts before any constructor (the executable's
// .preinit_array) and calls mkdir for its report directory while its interceptors are not yet set up: until then
// mkdir and mkdirat (the only calls seen that early) go straight to the kernel, untouched.
static int g_ready;
__attribute__((constructor)) static void mark_ready(void) { __atomic_store_n(&g_ready, 1, __ATOMIC_SEQ_CST); }

static void init(void) {
  const char* dir = getenv("COLORLAB_FAULT_DIR");
  const char* control = getenv("COLORLAB_FAULT_CONTROL");
  if (!dir || !control || !realpath(dir, g_dir)) {
    g_dir[0] = '\0';
    return;
  }
  snprintf(g_control, sizeof g_control, "%s", control);
}

// Reads the control file with raw system calls: the shim's own open and read must not recurse.
static void reload(void) {
  char text[PATH_MAX + 16] = {0};
  long fd = syscall(SYS_openat, AT_FDCWD, g_control, O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    __atomic_store_n(&g_errno, 0, __ATOMIC_SEQ_CST);
    __atomic_store_n(&g_hold, 0, __ATOMIC_SEQ_CST);
    return;
  }
  long n = syscall(SYS_read, (int)fd, text, sizeof text - 1);
  syscall(SYS_close, (int)fd);
  if (n < 0) n = 0;
  text[n] = '\0';
  char word[16] = {0}, sub[PATH_MAX] = {0};
  int fields = sscanf(text, "%15s %4095s", word, sub);
  __atomic_store_n(&g_errno,
                   fields >= 1 && strcmp(word, "ENOSPC") == 0 ? ENOSPC : fields >= 1 && strcmp(word, "EIO") == 0 ? EIO : 0,
                   __ATOMIC_SEQ_CST);
  __atomic_store_n(&g_hold, fields >= 1 && strcmp(word, "HOLD") == 0, __ATOMIC_SEQ_CST);
  if (fields == 2) {
    snprintf(g_scope, sizeof g_scope, "%s/%s", g_dir, sub);
    size_t len = strlen(g_scope);
    while (len > 1 && g_scope[len - 1] == '/') g_scope[--len] = '\0';
  } else {
    snprintf(g_scope, sizeof g_scope, "%s", g_dir);
  }
}

// The errno to fail with now (0: none), the control file re-read if it changed. The lock is only ever tried:
// a write from a signal handler (asio's self-pipe) that interrupts a thread holding it must not deadlock, so
// that call goes by the last state read (a switch takes effect a call later).
static int active_errno(void) {
  pthread_once(&g_once, init);
  if (!g_dir[0]) return 0;
  struct stat st;
  int present = stat(g_control, &st) == 0;
  if (pthread_mutex_trylock(&g_mutex) == 0) {
    if (!present) {
      __atomic_store_n(&g_errno, 0, __ATOMIC_SEQ_CST);
      __atomic_store_n(&g_hold, 0, __ATOMIC_SEQ_CST);
      g_seen_valid = 0;
    } else if (!g_seen_valid || st.st_ino != g_seen.st_ino || st.st_size != g_seen.st_size ||
               st.st_mtim.tv_sec != g_seen.st_mtim.tv_sec || st.st_mtim.tv_nsec != g_seen.st_mtim.tv_nsec) {
      reload();
      g_seen = st;
      g_seen_valid = 1;
    }
    pthread_mutex_unlock(&g_mutex);
  }
  return __atomic_load_n(&g_errno, __ATOMIC_SEQ_CST);
}

// Not in scope while another thread holds the lock (re-reading the scope): that call passes.
static int under_scope(const char* canonical) {
  if (pthread_mutex_trylock(&g_mutex) != 0) return 0;
  size_t n = strlen(g_scope);
  int inside = strncmp(canonical, g_scope, n) == 0 && (canonical[n] == '/' || canonical[n] == '\0');
  pthread_mutex_unlock(&g_mutex);
  return inside;
}

static int fd_in_scope(int fd) {
  char link[64], target[PATH_MAX];
  snprintf(link, sizeof link, "/proc/self/fd/%d", fd);
  ssize_t n = readlink(link, target, sizeof target - 1);
  if (n <= 0) return 0;  // sockets and pipes read "socket:[…]", never a path
  target[n] = '\0';
  return target[0] == '/' && under_scope(target);
}

// `path` (relative to `dirfd`) made canonical through its parent, which exists even when the entry does not.
static int path_in_scope(int dirfd, const char* path) {
  char joined[PATH_MAX * 2], parent[PATH_MAX], resolved[PATH_MAX];
  if (!path) return 0;
  if (path[0] == '/') {
    snprintf(joined, sizeof joined, "%s", path);
  } else {
    char base[PATH_MAX];
    if (dirfd == AT_FDCWD) {
      if (!getcwd(base, sizeof base)) return 0;
    } else {
      char link[64];
      snprintf(link, sizeof link, "/proc/self/fd/%d", dirfd);
      ssize_t n = readlink(link, base, sizeof base - 1);
      if (n <= 0) return 0;
      base[n] = '\0';
    }
    snprintf(joined, sizeof joined, "%s/%s", base, path);
  }
  size_t len = strlen(joined);
  while (len > 1 && joined[len - 1] == '/') joined[--len] = '\0';
  const char* slash = strrchr(joined, '/');
  const char* name = slash + 1;
  if (slash == joined) {
    snprintf(parent, sizeof parent, "/");
  } else {
    snprintf(parent, sizeof parent, "%.*s", (int)(slash - joined), joined);
  }
  if (!realpath(parent, resolved)) return 0;
  char full[PATH_MAX * 2];
  snprintf(full, sizeof full, "%s/%s", strcmp(resolved, "/") == 0 ? "" : resolved, name);
  return under_scope(full);
}

// dlsym hands back functions as object pointers; POSIX guarantees the conversion ISO C leaves open.
#pragma GCC diagnostic ignored "-Wpedantic"
#define REAL(name) ((__typeof__(&name))dlsym(RTLD_NEXT, #name))
#define FAIL_FD(fd)                          \
  do {                                       \
    int e_ = active_errno();                 \
    if (e_ && fd_in_scope(fd)) {             \
      errno = e_;                            \
      return -1;                             \
    }                                        \
  } while (0)

ssize_t write(int fd, const void* buf, size_t n) {
  FAIL_FD(fd);
  return REAL(write)(fd, buf, n);
}
ssize_t pwrite(int fd, const void* buf, size_t n, off_t off) {
  FAIL_FD(fd);
  return REAL(pwrite)(fd, buf, n, off);
}
ssize_t pwrite64(int fd, const void* buf, size_t n, off64_t off) {
  FAIL_FD(fd);
  return REAL(pwrite64)(fd, buf, n, off);
}
ssize_t writev(int fd, const struct iovec* iov, int count) {
  FAIL_FD(fd);
  return REAL(writev)(fd, iov, count);
}
ssize_t pwritev(int fd, const struct iovec* iov, int count, off_t off) {
  FAIL_FD(fd);
  return REAL(pwritev)(fd, iov, count, off);
}
// HOLD: the sync waits while the control file says HOLD, polling it every millisecond (at most 120 s, so a
// test that dies holding never leaves the process stuck for good).
static void hold_sync(int fd) {
  (void)active_errno();  // re-reads the control file if it changed
  if (!__atomic_load_n(&g_hold, __ATOMIC_SEQ_CST) || !fd_in_scope(fd)) return;
  char held[PATH_MAX + 8];
  snprintf(held, sizeof held, "%s.held", g_control);
  long h = syscall(SYS_openat, AT_FDCWD, held, O_WRONLY | O_CREAT | O_CLOEXEC, 0644);
  if (h >= 0) syscall(SYS_close, (int)h);
  for (int i = 0; i < 120000; ++i) {
    (void)active_errno();
    if (!__atomic_load_n(&g_hold, __ATOMIC_SEQ_CST)) return;
    struct timespec pause = {0, 1000000};
    nanosleep(&pause, NULL);
  }
}

int fsync(int fd) {
  hold_sync(fd);
  FAIL_FD(fd);
  return REAL(fsync)(fd);
}
int fdatasync(int fd) {
  hold_sync(fd);
  FAIL_FD(fd);
  return REAL(fdatasync)(fd);
}
int ftruncate(int fd, off_t length) {
  FAIL_FD(fd);
  return REAL(ftruncate)(fd, length);
}
int ftruncate64(int fd, off64_t length) {
  FAIL_FD(fd);
  return REAL(ftruncate64)(fd, length);
}
int fallocate(int fd, int mode, off_t off, off_t len) {
  FAIL_FD(fd);
  return REAL(fallocate)(fd, mode, off, len);
}
int fallocate64(int fd, int mode, off64_t off, off64_t len) {
  FAIL_FD(fd);
  return REAL(fallocate64)(fd, mode, off, len);
}
// posix_fallocate reports its error as the return value, not through errno.
int posix_fallocate(int fd, off_t off, off_t len) {
  int e = active_errno();
  if (e && fd_in_scope(fd)) return e;
  return REAL(posix_fallocate)(fd, off, len);
}
int posix_fallocate64(int fd, off64_t off, off64_t len) {
  int e = active_errno();
  if (e && fd_in_scope(fd)) return e;
  return REAL(posix_fallocate64)(fd, off, len);
}

// glibc's stdio writes through internal calls the shim cannot see: a stream opened for writing there fails at
// fopen instead, the nearest the shim can come to its first write failing.
static int refuse_stream(const char* path, const char* mode) {
  if (!mode || !strpbrk(mode, "wa+")) return 0;
  int e = active_errno();
  if (!e || !path_in_scope(AT_FDCWD, path)) return 0;
  errno = e;
  return 1;
}
FILE* fopen(const char* path, const char* mode) {
  if (refuse_stream(path, mode)) return NULL;
  return REAL(fopen)(path, mode);
}
FILE* fopen64(const char* path, const char* mode) {
  if (refuse_stream(path, mode)) return NULL;
  return REAL(fopen64)(path, mode);
}

// A new directory needs a block of its own: refused on a full disk.
static int refuse_entry(int dirfd, const char* path) {
  int e = active_errno();
  if (e != ENOSPC || !path_in_scope(dirfd, path)) return 0;
  errno = e;
  return 1;
}
int mkdir(const char* path, mode_t mode) {
  if (!__atomic_load_n(&g_ready, __ATOMIC_SEQ_CST)) return (int)syscall(SYS_mkdirat, AT_FDCWD, path, mode);
  if (refuse_entry(AT_FDCWD, path)) return -1;
  return REAL(mkdir)(path, mode);
}
int mkdirat(int dirfd, const char* path, mode_t mode) {
  if (!__atomic_load_n(&g_ready, __ATOMIC_SEQ_CST)) return (int)syscall(SYS_mkdirat, dirfd, path, mode);
  if (refuse_entry(dirfd, path)) return -1;
  return REAL(mkdirat)(dirfd, path, mode);
}
