# The linker: GCC's default, GNU ld. Debian 12's lld (14) links 3-4x faster, but executables it linked
# did not catch some exceptions (`colorlab` aborted with "terminate called" on a TLS error instead of
# exiting 1; access_daemon.TlsOnLoopbackIsVerifiedAgainstTheGivenCa caught it), so it is not the default
# (docs/PERFORMANCE.md, "CI time"). Where the chosen linker is missing, the compiler's default is kept.
set(COLORLAB_LINKER "" CACHE STRING "Linker passed as -fuse-ld= (bfd, gold, lld; empty: the compiler's default)")
if(COLORLAB_LINKER)
  include(CheckLinkerFlag)
  check_linker_flag(CXX -fuse-ld=${COLORLAB_LINKER} COLORLAB_HAVE_LINKER_${COLORLAB_LINKER})
  if(COLORLAB_HAVE_LINKER_${COLORLAB_LINKER})
    add_link_options(-fuse-ld=${COLORLAB_LINKER})
  else()
    message(STATUS "colorlab: -fuse-ld=${COLORLAB_LINKER} does not link (apt-get install lld); the compiler's default linker")
  endif()
endif()
