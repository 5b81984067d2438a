include(CMakePackageConfigHelpers)

# One export set per component, so that a host loads only what it asks for and needs only that part's
# dependencies: core (dyncull, pipeline) Eigen; opencv the OpenCV modules; opencv_dnn those and dnn;
# culler OpenCV core (and calib3d at link time); host the culler, OpenCV core, imgproc and dnn (at link time)
# and threads; ceres Ceres.
set(DYNCULL_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/dyncull)
set(DYNCULL_CORE_TARGETS dyncull)
if(DYNCULL_MASTER_PROJECT)  # otherwise dyncull_pipeline is built only when a target links it
  list(APPEND DYNCULL_CORE_TARGETS dyncull_pipeline)
endif()
install(TARGETS ${DYNCULL_CORE_TARGETS} EXPORT dyncullTargets)
install(EXPORT dyncullTargets NAMESPACE dyncull:: DESTINATION ${DYNCULL_CMAKE_DIR})
set(DYNCULL_COMPONENTS "")
foreach(_comp opencv opencv_dnn culler host ceres)
  if(TARGET dyncull_${_comp})
    list(APPEND DYNCULL_COMPONENTS ${_comp})
    install(TARGETS dyncull_${_comp} EXPORT dyncull-${_comp}Targets)
    install(EXPORT dyncull-${_comp}Targets NAMESPACE dyncull:: DESTINATION ${DYNCULL_CMAKE_DIR})
  endif()
endforeach()
install(DIRECTORY include/dyncull DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(FILES "${CMAKE_CURRENT_BINARY_DIR}/generated/include/dyncull/version.hpp"
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/dyncull)

configure_package_config_file(cmake/dyncullConfig.cmake.in
  "${CMAKE_CURRENT_BINARY_DIR}/dyncullConfig.cmake"
  INSTALL_DESTINATION ${DYNCULL_CMAKE_DIR})
write_basic_package_version_file("${CMAKE_CURRENT_BINARY_DIR}/dyncullConfigVersion.cmake"
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMajorVersion ARCH_INDEPENDENT)
install(FILES "${CMAKE_CURRENT_BINARY_DIR}/dyncullConfig.cmake"
              "${CMAKE_CURRENT_BINARY_DIR}/dyncullConfigVersion.cmake"
        DESTINATION ${DYNCULL_CMAKE_DIR})
