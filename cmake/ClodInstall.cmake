include(GNUInstallDirs)
include(CMakePackageConfigHelpers)
install(TARGETS clod ${CLOD_LAYER_TARGETS} EXPORT clodTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
if(TARGET clod_cli)
  install(TARGETS clod_cli RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
endif()
install(DIRECTORY include/clod DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(EXPORT clodTargets NAMESPACE clod:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/clod)
file(WRITE ${PROJECT_BINARY_DIR}/clodConfig.cmake.in [=[
@PACKAGE_INIT@
include(CMakeFindDependencyMacro)
find_dependency(Eigen3 3.4 NO_MODULE)
find_dependency(TBB)
find_dependency(assimp)
find_dependency(Qhull)
find_dependency(nlohmann_json)
find_dependency(TinyGLTF)
include("${CMAKE_CURRENT_LIST_DIR}/clodTargets.cmake")
]=])
configure_package_config_file(${PROJECT_BINARY_DIR}/clodConfig.cmake.in
  ${PROJECT_BINARY_DIR}/clodConfig.cmake INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/clod)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/clodConfigVersion.cmake COMPATIBILITY SameMajorVersion)
install(FILES ${PROJECT_BINARY_DIR}/clodConfig.cmake ${PROJECT_BINARY_DIR}/clodConfigVersion.cmake
  DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/clod)
