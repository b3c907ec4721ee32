# Engines embed Rivulet through find_package(rivulet) -> rivulet::rivulet.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)
install(TARGETS rivulet rivulet_jobs rivulet_systems rivulet_runtime rivulet_options EXPORT rivuletTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(TARGETS rivulet_cli RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
# Only the public API's headers: consumers include <rivulet/...>; the internals stay private.
install(DIRECTORY include/rivulet DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} FILES_MATCHING PATTERN "*.h")
install(FILES ${PROJECT_BINARY_DIR}/include/rivulet/version.h DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/rivulet)
install(EXPORT rivuletTargets NAMESPACE rivulet:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/rivulet)
configure_package_config_file(cmake/rivuletConfig.cmake.in ${PROJECT_BINARY_DIR}/rivuletConfig.cmake
                              INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/rivulet)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/rivuletConfigVersion.cmake COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/rivuletConfig.cmake ${PROJECT_BINARY_DIR}/rivuletConfigVersion.cmake
        DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/rivulet)
