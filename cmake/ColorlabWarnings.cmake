# Warnings are attached per target (never globally) so third-party headers stay quiet.
function(colorlab_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wno-missing-field-initializers)
endfunction()

# Adds every immediate subdirectory that has a CMakeLists.txt, in name order, so that parts of a
# module can be owned and grown independently.
macro(colorlab_add_existing_subdirectories)
  file(GLOB _colorlab_children LIST_DIRECTORIES true RELATIVE ${CMAKE_CURRENT_SOURCE_DIR} ${CMAKE_CURRENT_SOURCE_DIR}/*)
  list(SORT _colorlab_children)
  foreach(_child IN LISTS _colorlab_children)
    if(IS_DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR}/${_child} AND EXISTS ${CMAKE_CURRENT_SOURCE_DIR}/${_child}/CMakeLists.txt)
      add_subdirectory(${_child})
    endif()
  endforeach()
endmacro()
