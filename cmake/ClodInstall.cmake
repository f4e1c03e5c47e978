# `cmake --install` lays out include/clod, the layer libraries, the CLI, a CMake package
# (find_package(clod [COMPONENTS core io world scene]) -> clod::<component>, clod::clod) and one
# pkg-config file per component plus clod.pc. tests/package checks both routes from a project
# outside this tree, and that a core-only consumer needs none of the I/O libraries.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

# One export set per component (clodCoreTargets.cmake, ...): its layers and its INTERFACE target.
# A component's file refers to the targets of the components it needs, which clodConfig.cmake
# loads first; clod::clod has a file of its own, loaded when every component is.
foreach(component ${CLOD_COMPONENTS})
  string(SUBSTRING ${component} 0 1 first)
  string(TOUPPER ${first} first)
  string(SUBSTRING ${component} 1 -1 rest)
  get_property(component_layers GLOBAL PROPERTY CLOD_COMPONENT_${component}_LAYERS)
  install(TARGETS clod_component_${component} ${component_layers} EXPORT clod${first}${rest}Targets
    ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
    LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
    RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR}
    INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
  install(EXPORT clod${first}${rest}Targets NAMESPACE clod:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/clod)
endforeach()
install(TARGETS clod EXPORT clodTargets)
install(EXPORT clodTargets NAMESPACE clod:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/clod)
if(TARGET clod_cli)
  install(TARGETS clod_cli RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
endif()
install(DIRECTORY include/clod DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(FILES ${PROJECT_BINARY_DIR}/include/clod/version.h DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/clod)
install(FILES LICENSE DESTINATION ${CMAKE_INSTALL_DOCDIR})

configure_package_config_file(cmake/clodConfig.cmake.in ${PROJECT_BINARY_DIR}/clodConfig.cmake
  INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/clod)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/clodConfigVersion.cmake COMPATIBILITY SameMajorVersion)
install(FILES ${PROJECT_BINARY_DIR}/clodConfig.cmake ${PROJECT_BINARY_DIR}/clodConfigVersion.cmake
  DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/clod)

# pkg-config: clod-<component>.pc per component, and clod.pc (all of them). A component's layers go
# on its link line top layer first (static linking resolves left to right), and pkg-config puts a
# package's libraries before those of the packages it Requires. Static libraries need their
# dependencies' libraries on a plain `--libs` line, so those are Requires; shared ones carry their
# own, so only Eigen (used in the headers) is. The pkg-config names of each component's own
# dependencies (the Debian packages' .pc files):
set(CLOD_PC_DEPS_core "tbb qhull_r libxxhash")
set(CLOD_PC_DEPS_io "tbb assimp")
set(CLOD_PC_DEPS_world "tbb")
set(CLOD_PC_DEPS_scene "tbb nlohmann_json tinygltf")
set(CLOD_PC_DESCRIPTION_core "narrow phase: meshes, proximity, sphere-trees, closest feature maps, contact trees, bakes")
set(CLOD_PC_DESCRIPTION_io "mesh file readers (OBJ, STL, PLY, OFF, glTF, Collada)")
set(CLOD_PC_DESCRIPTION_world "rigid-body World on the narrow phase")
set(CLOD_PC_DESCRIPTION_scene "JSON scenes, glTF export, plausibility experiments")
# Relative, so the installed tree can be moved (or installed with --prefix elsewhere).
file(RELATIVE_PATH CLOD_PC_PREFIX_FROM_PCDIR "/prefix/${CMAKE_INSTALL_LIBDIR}/pkgconfig" "/prefix")
string(REGEX REPLACE "/$" "" CLOD_PC_PREFIX_FROM_PCDIR "${CLOD_PC_PREFIX_FROM_PCDIR}")

function(clod_write_pc file name description libs requires_own needs)
  list(TRANSFORM needs PREPEND clod- OUTPUT_VARIABLE needed_pcs)
  string(REPLACE ";" " " needed_pcs "${needed_pcs}")
  set(CLOD_PC_NAME ${name})
  set(CLOD_PC_DESCRIPTION ${description})
  set(CLOD_PC_LIBS "${libs}")
  if(CLOD_BUILD_SHARED)
    set(CLOD_PC_REQUIRES "${needed_pcs} eigen3")
    set(CLOD_PC_REQUIRES_PRIVATE "${requires_own}")
  else()
    set(CLOD_PC_REQUIRES "${needed_pcs} eigen3 ${requires_own}")
    set(CLOD_PC_REQUIRES_PRIVATE "")
  endif()
  string(STRIP "${CLOD_PC_REQUIRES}" CLOD_PC_REQUIRES)
  configure_file(${PROJECT_SOURCE_DIR}/cmake/clod.pc.in ${PROJECT_BINARY_DIR}/${file} @ONLY)
  install(FILES ${PROJECT_BINARY_DIR}/${file} DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
endfunction()

foreach(component ${CLOD_COMPONENTS})
  get_property(component_layers GLOBAL PROPERTY CLOD_COMPONENT_${component}_LAYERS)
  get_property(needs GLOBAL PROPERTY CLOD_COMPONENT_${component}_NEEDS)
  set(libs "")
  foreach(layer ${component_layers})
    set(libs "-l${layer} ${libs}")
  endforeach()
  string(STRIP "${libs}" libs)
  clod_write_pc(clod-${component}.pc clod-${component} "clod ${CLOD_PC_DESCRIPTION_${component}}"
    "${libs}" "${CLOD_PC_DEPS_${component}}" "${needs}")
endforeach()
# clod.pc: every component, the top ones first (as for the layers).
set(components_top_first ${CLOD_COMPONENTS})
list(REVERSE components_top_first)
clod_write_pc(clod.pc clod
  "Time-critical collision detection and contact generation between rigid triangle meshes (every component)"
  "" "" "${components_top_first}")
