# Warning flags for dyncull's own executables (never put on the INTERFACE target: they are
# the consumer's choice).
include(GNUInstallDirs)

function(dyncull_set_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic)
  if(DYNCULL_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
endfunction()

# Name a target after its path below a root: tests/geometry/fundamental_test.cpp -> geometry_fundamental_test
function(dyncull_target_name_from_path out root file)
  file(RELATIVE_PATH rel "${root}" "${file}")
  get_filename_component(dir "${rel}" DIRECTORY)
  get_filename_component(stem "${rel}" NAME_WE)
  if(dir)
    string(REPLACE "/" "_" dir "${dir}")
    set(${out} "${dir}_${stem}" PARENT_SCOPE)
  else()
    set(${out} "${stem}" PARENT_SCOPE)
  endif()
endfunction()
