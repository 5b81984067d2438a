include(CMakePackageConfigHelpers)

set(DYNCULL_EXPORT_TARGETS dyncull)
if(DYNCULL_MASTER_PROJECT)  # otherwise dyncull_pipeline is built only when a target links it
  list(APPEND DYNCULL_EXPORT_TARGETS dyncull_pipeline)
endif()
if(DYNCULL_HAS_OPENCV)
  list(APPEND DYNCULL_EXPORT_TARGETS dyncull_opencv)
endif()
if(DYNCULL_HAS_OPENCV_DNN)
  list(APPEND DYNCULL_EXPORT_TARGETS dyncull_opencv_dnn)
endif()
if(DYNCULL_HAS_CERES)
  list(APPEND DYNCULL_EXPORT_TARGETS dyncull_ceres)
endif()
if(TARGET dyncull_culler)
  list(APPEND DYNCULL_EXPORT_TARGETS dyncull_culler)
endif()

install(TARGETS ${DYNCULL_EXPORT_TARGETS} EXPORT dyncullTargets)
install(DIRECTORY include/dyncull DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(FILES "${CMAKE_CURRENT_BINARY_DIR}/generated/include/dyncull/version.hpp"
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/dyncull)

set(DYNCULL_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/dyncull)
install(EXPORT dyncullTargets NAMESPACE dyncull:: DESTINATION ${DYNCULL_CMAKE_DIR})

configure_package_config_file(cmake/dyncullConfig.cmake.in
  "${CMAKE_CURRENT_BINARY_DIR}/dyncullConfig.cmake"
  INSTALL_DESTINATION ${DYNCULL_CMAKE_DIR})
write_basic_package_version_file("${CMAKE_CURRENT_BINARY_DIR}/dyncullConfigVersion.cmake"
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMajorVersion ARCH_INDEPENDENT)
install(FILES "${CMAKE_CURRENT_BINARY_DIR}/dyncullConfig.cmake"
              "${CMAKE_CURRENT_BINARY_DIR}/dyncullConfigVersion.cmake"
        DESTINATION ${DYNCULL_CMAKE_DIR})
