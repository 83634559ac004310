// The fault shim on its own: this program re-runs itself under LD_PRELOAD with a fresh fault directory and
// checks every intercepted call inside it, beside it (a sibling whose name shares the prefix), on a socket,
// and across the switch (off, ENOSPC, EIO in a subdirectory only, off again: space returned). Creating and
// renaming files are never refused, as on a real full disk: a writer gets as far as a half-written file.
#define _GNU_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/uio.h>
#include <unistd.h>

static int g_failures;

#define CHECK(cond, ...)                                 \
  do {                                                   \
    if (!(cond)) {                                       \
      fprintf(stderr, "FAIL line %d: ", __LINE__);       \
      fprintf(stderr, __VA_ARGS__);                      \
      fprintf(stderr, " (errno %s)\n", strerror(errno)); \
      ++g_failures;                                      \
    }                                                    \
  } while (0)

static char g_root[256], g_dir[300], g_sub[320], g_sibling[320], g_control[320];

static void set_control(const char* text) {
  char tmp[400];
  snprintf(tmp, sizeof tmp, "%s.tmp", g_control);
  FILE* f = fopen(tmp, "w");
  if (!f || fputs(text, f) < 0 || fclose(f) != 0 || rename(tmp, g_control) != 0) {
    fprintf(stderr, "cannot write the control file %s\n", g_control);
    exit(2);
  }
}

static void path_in(char* out, size_t n, const char* dir, const char* name) { snprintf(out, n, "%s/%s", dir, name); }

// Every way of writing an existing file at `dir`/existing: `want` is 0 (all succeed) or the errno each must fail with.
static void expect_writes(const char* dir, int want, const char* what) {
  char path[400];
  path_in(path, sizeof path, dir, "existing");
  int fd = open(path, O_RDWR | O_CREAT, 0644);  // existing: opens even on a full disk
  CHECK(fd >= 0, "%s: open existing %s", what, path);
  if (fd < 0) return;
  errno = 0;
  ssize_t w = write(fd, "abc", 3);
  CHECK(want ? (w < 0 && errno == want) : w == 3, "%s: write", what);
  errno = 0;
  w = pwrite(fd, "abc", 3, 10);
  CHECK(want ? (w < 0 && errno == want) : w == 3, "%s: pwrite", what);
  struct iovec iov[2] = {{"a", 1}, {"b", 1}};
  errno = 0;
  w = writev(fd, iov, 2);
  CHECK(want ? (w < 0 && errno == want) : w == 2, "%s: writev", what);
  errno = 0;
  int r = fsync(fd);
  CHECK(want ? (r < 0 && errno == want) : r == 0, "%s: fsync", what);
  errno = 0;
  r = fdatasync(fd);
  CHECK(want ? (r < 0 && errno == want) : r == 0, "%s: fdatasync", what);
  errno = 0;
  r = ftruncate(fd, 4);
  CHECK(want ? (r < 0 && errno == want) : r == 0, "%s: ftruncate", what);
  r = posix_fallocate(fd, 0, 4096);
  CHECK(r == want, "%s: posix_fallocate returned %d", what, r);
  char buf[4];
  CHECK(pread(fd, buf, sizeof buf, 0) >= 0, "%s: pread is never refused", what);
  close(fd);

  // A full disk still has inodes: a new file is created, and its first write fails.
  char fresh[400], dirpath[400], target[400];
  path_in(fresh, sizeof fresh, dir, "fresh");
  int nfd = open(fresh, O_WRONLY | O_CREAT | O_EXCL, 0644);
  CHECK(nfd >= 0, "%s: open O_CREAT of a new file", what);
  errno = 0;
  w = nfd >= 0 ? write(nfd, "abc", 3) : -1;
  CHECK(want ? (w < 0 && errno == want) : w == 3, "%s: the new file's first write", what);
  if (nfd >= 0) close(nfd);
  CHECK(unlink(fresh) == 0, "%s: unlink frees space and is never refused", what);
  int dfd = open(dir, O_RDONLY | O_DIRECTORY);
  nfd = openat(dfd, "fresh-at", O_WRONLY | O_CREAT | O_TRUNC, 0644);
  CHECK(nfd >= 0, "%s: openat O_CREAT relative to the directory", what);
  errno = 0;
  w = nfd >= 0 ? write(nfd, "abc", 3) : -1;
  CHECK(want ? (w < 0 && errno == want) : w == 3, "%s: write through openat", what);
  if (nfd >= 0) close(nfd);
  unlinkat(dfd, "fresh-at", 0);
  close(dfd);
  errno = 0;
  FILE* f = fopen(fresh, "w");
  CHECK(want ? (f == NULL && errno == want) : f != NULL, "%s: fopen for writing", what);
  if (f) fclose(f);
  unlink(fresh);
  // A directory needs a block: refused on a full disk only.
  path_in(dirpath, sizeof dirpath, dir, "newdir");
  errno = 0;
  r = mkdir(dirpath, 0755);
  CHECK(want == ENOSPC ? (r < 0 && errno == ENOSPC) : r == 0, "%s: mkdir", what);
  rmdir(dirpath);
  // Renaming a whole file into the directory stores no new data.
  char outside[400];
  path_in(outside, sizeof outside, g_root, "outside-file");
  close(open(outside, O_WRONLY | O_CREAT | O_TRUNC, 0644));
  path_in(target, sizeof target, dir, "renamed");
  CHECK(rename(outside, target) == 0, "%s: rename into", what);
  unlink(target);
  unlink(outside);
}

static int child(void) {
  int sv[2];
  if (socketpair(AF_UNIX, SOCK_STREAM, 0, sv) != 0) return 2;

  expect_writes(g_dir, 0, "no control file");
  set_control("off\n");
  expect_writes(g_dir, 0, "off");

  set_control("ENOSPC\n");
  expect_writes(g_dir, ENOSPC, "ENOSPC, the directory");
  expect_writes(g_sub, ENOSPC, "ENOSPC, a subdirectory");
  expect_writes(g_sibling, 0, "ENOSPC, a sibling sharing the name's prefix");
  expect_writes(g_root, 0, "ENOSPC, the parent");
  CHECK(write(sv[0], "x", 1) == 1, "ENOSPC: a socket is never refused");
  char existing[400];
  path_in(existing, sizeof existing, g_dir, "existing");
  CHECK(unlink(existing) == 0, "ENOSPC: unlink of an existing file");
  set_control("off\n");
  close(open(existing, O_WRONLY | O_CREAT, 0644));

  set_control("EIO sub\n");
  expect_writes(g_sub, EIO, "EIO sub, the subdirectory");
  expect_writes(g_dir, 0, "EIO sub, the directory outside sub");

  // Space returns: a descriptor opened while the disk was full writes again.
  set_control("ENOSPC\n");
  int fd = open(existing, O_RDWR | O_CREAT, 0644);
  CHECK(fd >= 0 && write(fd, "a", 1) < 0 && errno == ENOSPC, "ENOSPC: write on a descriptor opened while full");
  CHECK(unlink(g_control) == 0, "remove the control file");
  CHECK(write(fd, "a", 1) == 1, "removed control file: the same descriptor writes again");
  close(fd);
  expect_writes(g_dir, 0, "control file removed");
  close(sv[0]);
  close(sv[1]);
  char cleanup[400];
  snprintf(cleanup, sizeof cleanup, "rm -rf '%s'", g_root);
  if (system(cleanup) != 0) fprintf(stderr, "could not remove %s\n", g_root);
  if (g_failures) fprintf(stderr, "%d check(s) failed\n", g_failures);
  else printf("faultshim: all checks passed\n");
  return g_failures ? 1 : 0;
}

int main(int argc, char** argv) {
  (void)argc;
  const char* root = getenv("FAULTSHIM_TEST_ROOT");
  if (root) {
    snprintf(g_root, sizeof g_root, "%s", root);
    path_in(g_dir, sizeof g_dir, g_root, "state");
    path_in(g_sub, sizeof g_sub, g_dir, "sub");
    path_in(g_sibling, sizeof g_sibling, g_root, "state-other");
    path_in(g_control, sizeof g_control, g_root, "control");
    return child();
  }
  char tmpl[] = "/tmp/faultshim-test-XXXXXX";
  if (!mkdtemp(tmpl)) return 2;
  snprintf(g_root, sizeof g_root, "%s", tmpl);
  path_in(g_dir, sizeof g_dir, g_root, "state");
  path_in(g_sub, sizeof g_sub, g_dir, "sub");
  path_in(g_sibling, sizeof g_sibling, g_root, "state-other");
  path_in(g_control, sizeof g_control, g_root, "control");
  if (mkdir(g_dir, 0755) || mkdir(g_sub, 0755) || mkdir(g_sibling, 0755)) return 2;
  // Files that exist before the disk fills: opening them stays possible, writing them does not.
  for (const char* d = g_dir; d; d = d == g_dir ? g_sub : NULL) {
    char existing[400];
    path_in(existing, sizeof existing, d, "existing");
    close(open(existing, O_WRONLY | O_CREAT, 0644));
  }
  setenv("FAULTSHIM_TEST_ROOT", g_root, 1);
  setenv("LD_PRELOAD", COLORLAB_FAULTSHIM, 1);
  setenv("COLORLAB_FAULT_DIR", g_dir, 1);
  setenv("COLORLAB_FAULT_CONTROL", g_control, 1);
  // Under the asan preset the shim is not the first library; ASan's link-order check would refuse to start.
  setenv("ASAN_OPTIONS", "verify_asan_link_order=0", 1);
  execv("/proc/self/exe", argv);
  perror("execv");
  return 2;
}
