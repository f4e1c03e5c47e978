# `cmake --install` lays out include/clod, the layer libraries, the CLI, a CMake package
# (find_package(clod) -> clod::clod) and a pkg-config file (clod.pc). tests/package checks that
# both work from a project outside this tree.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)
install(TARGETS clod ${CLOD_LAYER_TARGETS} EXPORT clodTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR}
  INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
if(TARGET clod_cli)
  install(TARGETS clod_cli RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
endif()
install(DIRECTORY include/clod DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(FILES ${PROJECT_BINARY_DIR}/include/clod/version.h DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/clod)
install(FILES LICENSE DESTINATION ${CMAKE_INSTALL_DOCDIR})

install(EXPORT clodTargets NAMESPACE clod:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/clod)
configure_package_config_file(cmake/clodConfig.cmake.in ${PROJECT_BINARY_DIR}/clodConfig.cmake
  INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/clod)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/clodConfigVersion.cmake COMPATIBILITY SameMajorVersion)
install(FILES ${PROJECT_BINARY_DIR}/clodConfig.cmake ${PROJECT_BINARY_DIR}/clodConfigVersion.cmake
  DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/clod)

# clod.pc. The layers go on the link line top layer first (static linking resolves left to
# right). Static libraries need their dependencies' libraries on a plain `--libs` line, so those
# are Requires; shared ones carry their own, so only Eigen (used in the headers) is.
set(CLOD_PC_LIBS "")
foreach(layer ${CLOD_LAYER_TARGETS})
  set(CLOD_PC_LIBS "-l${layer} ${CLOD_PC_LIBS}")
endforeach()
string(STRIP "${CLOD_PC_LIBS}" CLOD_PC_LIBS)
set(clod_pc_deps "tbb assimp qhull_r libxxhash tinygltf nlohmann_json")
if(CLOD_BUILD_SHARED)
  set(CLOD_PC_REQUIRES "eigen3")
  set(CLOD_PC_REQUIRES_PRIVATE "${clod_pc_deps}")
else()
  set(CLOD_PC_REQUIRES "eigen3 ${clod_pc_deps}")
  set(CLOD_PC_REQUIRES_PRIVATE "")
endif()
# Relative, so the installed tree can be moved (or installed with --prefix elsewhere).
file(RELATIVE_PATH CLOD_PC_PREFIX_FROM_PCDIR "/prefix/${CMAKE_INSTALL_LIBDIR}/pkgconfig" "/prefix")
string(REGEX REPLACE "/$" "" CLOD_PC_PREFIX_FROM_PCDIR "${CLOD_PC_PREFIX_FROM_PCDIR}")
configure_file(cmake/clod.pc.in ${PROJECT_BINARY_DIR}/clod.pc @ONLY)
install(FILES ${PROJECT_BINARY_DIR}/clod.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
