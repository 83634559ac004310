# The linker. RelWithDebInfo links 110 executables carrying full debug info; GNU ld (bfd) spends most
# of a link copying that debug info, which lld (Debian's `lld`, scripts/setup.sh) does several times faster
# (docs/PERFORMANCE.md, "CI time"). Where the chosen linker is missing, the compiler's default is kept.
# Debugging is unchanged: the same DWARF ends up in the same executables.
set(COLORLAB_LINKER lld CACHE STRING "Linker passed as -fuse-ld= (lld, gold, bfd; empty: the compiler's default)")
if(COLORLAB_LINKER)
  include(CheckLinkerFlag)
  check_linker_flag(CXX -fuse-ld=${COLORLAB_LINKER} COLORLAB_HAVE_LINKER_${COLORLAB_LINKER})
  if(COLORLAB_HAVE_LINKER_${COLORLAB_LINKER})
    add_link_options(-fuse-ld=${COLORLAB_LINKER})
  else()
    message(STATUS "colorlab: -fuse-ld=${COLORLAB_LINKER} does not link (apt-get install lld); the compiler's default linker")
  endif()
endif()
