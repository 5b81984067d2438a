# The `doc` target: dyncull's HTML API reference from the headers' comments (Doxygen), written to
# <build dir>/doc/html; any Doxygen warning fails the build. Without Doxygen the target explains how
# to get it (Debian: apt-get install doxygen graphviz, as scripts/install-deps.sh does).
find_package(Doxygen QUIET OPTIONAL_COMPONENTS dot)
if(DOXYGEN_FOUND)
  set(DYNCULL_DOC_OUTPUT_DIR "${CMAKE_CURRENT_BINARY_DIR}/doc")
  if(TARGET Doxygen::dot)
    set(DYNCULL_DOC_HAVE_DOT YES)
  else()
    set(DYNCULL_DOC_HAVE_DOT NO)
  endif()
  configure_file("${CMAKE_CURRENT_SOURCE_DIR}/docs/Doxyfile.in" "${DYNCULL_DOC_OUTPUT_DIR}/Doxyfile" @ONLY)
  file(GLOB_RECURSE _dyncull_doc_inputs CONFIGURE_DEPENDS
    "${CMAKE_CURRENT_SOURCE_DIR}/include/dyncull/*.hpp" "${CMAKE_CURRENT_SOURCE_DIR}/docs/*.md")
  add_custom_command(
    OUTPUT "${DYNCULL_DOC_OUTPUT_DIR}/doxygen.stamp"
    COMMAND "${CMAKE_COMMAND}" -E remove -f "${DYNCULL_DOC_OUTPUT_DIR}/doxygen.stamp"
    COMMAND Doxygen::doxygen "${DYNCULL_DOC_OUTPUT_DIR}/Doxyfile"
    COMMAND "${CMAKE_COMMAND}" -E touch "${DYNCULL_DOC_OUTPUT_DIR}/doxygen.stamp"
    DEPENDS "${DYNCULL_DOC_OUTPUT_DIR}/Doxyfile" "${CMAKE_CURRENT_SOURCE_DIR}/README.md" ${_dyncull_doc_inputs}
    WORKING_DIRECTORY "${CMAKE_CURRENT_SOURCE_DIR}"
    COMMENT "Doxygen: API reference in ${DYNCULL_DOC_OUTPUT_DIR}/html (warnings are errors)"
    VERBATIM)
  add_custom_target(doc DEPENDS "${DYNCULL_DOC_OUTPUT_DIR}/doxygen.stamp")
  message(STATUS "dyncull: API reference target `doc` (Doxygen ${DOXYGEN_VERSION})")
else()
  add_custom_target(doc
    COMMAND "${CMAKE_COMMAND}" -E echo
            "dyncull: Doxygen not found; install it (Debian: apt-get install doxygen graphviz) and re-run cmake"
    COMMAND "${CMAKE_COMMAND}" -E false
    VERBATIM)
  message(STATUS "dyncull: Doxygen not found, the `doc` target only says so (apt-get install doxygen graphviz)")
endif()
