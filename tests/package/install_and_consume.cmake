# ctest package/install_and_consume: installs this build tree into a fresh prefix, then builds
# and runs tests/package/consumer twice from outside the tree -- once through
# find_package(clod) and once through `pkg-config --cflags --libs clod` -- the two ways the
# README tells users to adopt clod. Then the same program as a core-only user (consumer_core:
# find_package(clod COMPONENTS core), and clod-core.pc), which must configure with the Assimp,
# JSON and glTF packages made unfindable, link none of them and none of clod's I/O layers.
# Nothing is downloaded; it fails on the first step that does.
#
#   cmake -DCLOD_BINARY_DIR=... -DCONSUMER_DIR=... -DWORK_DIR=... -DGENERATOR=... -DCXX=...
#         [-DLAUNCHER=ccache] -DPKG_CONFIG=... -P install_and_consume.cmake
foreach(var CLOD_BINARY_DIR CONSUMER_DIR WORK_DIR GENERATOR CXX PKG_CONFIG)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "install_and_consume.cmake: -D${var}=... is required")
  endif()
endforeach()

# Runs a command; on failure prints what it said and stops the test.
function(step name)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${name} failed (${rc}):\n${ARGN}\n${out}\n${err}")
  endif()
  set(step_output "${out}" PARENT_SCOPE)
endfunction()

# The consumer must print matching header and library versions, and a contact between the boxes.
function(check_consumer name output)
  if(NOT output MATCHES "clod headers ([0-9.]+), library ([0-9.]+)" OR NOT CMAKE_MATCH_1 STREQUAL CMAKE_MATCH_2)
    message(FATAL_ERROR "${name}: unexpected output:\n${output}")
  endif()
  if(NOT output MATCHES "colliding 1, contacts [1-9]")
    message(FATAL_ERROR "${name}: the boxes did not collide:\n${output}")
  endif()
  message(STATUS "${name}: ${output}")
endfunction()

set(prefix ${WORK_DIR}/prefix)
file(REMOVE_RECURSE ${WORK_DIR})
step("install" ${CMAKE_COMMAND} --install ${CLOD_BINARY_DIR} --prefix ${prefix})
# 0. The installed tool starts from the prefix alone (a shared build: every library it links is
# installed, and found through its run path).
if(EXISTS ${prefix}/bin/clod)
  step("installed clod --version" ${prefix}/bin/clod --version)
  message(STATUS "installed tool: ${step_output}")
endif()

# 1. CMake: find_package(clod REQUIRED) with only the fresh prefix to find it in.
set(launcher "")
if(LAUNCHER)
  set(launcher -DCMAKE_CXX_COMPILER_LAUNCHER=${LAUNCHER})
endif()
step("consumer configure (find_package)" ${CMAKE_COMMAND} -S ${CONSUMER_DIR} -B ${WORK_DIR}/cmake-build
     -G ${GENERATOR} -DCMAKE_BUILD_TYPE= -DCMAKE_CXX_COMPILER=${CXX} ${launcher}
     -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF)
file(STRINGS ${WORK_DIR}/cmake-build/CMakeCache.txt clod_dir REGEX "^clod_DIR:")
if(NOT clod_dir MATCHES "=${prefix}/")
  message(FATAL_ERROR "find_package(clod) found a clod outside the fresh prefix: ${clod_dir}")
endif()
step("consumer build (find_package)" ${CMAKE_COMMAND} --build ${WORK_DIR}/cmake-build)
step("consumer run (find_package)" ${WORK_DIR}/cmake-build/clod_consumer)
check_consumer("find_package" "${step_output}")

# 2. pkg-config: the flags clod.pc gives, straight onto a compiler command line.
file(GLOB_RECURSE pc_files ${prefix}/*/clod.pc)
list(LENGTH pc_files pc_count)
if(NOT pc_count EQUAL 1)
  message(FATAL_ERROR "expected one installed clod.pc under ${prefix}, found: ${pc_files}")
endif()
get_filename_component(pc_dir ${pc_files} DIRECTORY)
set(ENV{PKG_CONFIG_PATH} ${pc_dir})
step("pkg-config" ${PKG_CONFIG} --cflags --libs clod)
separate_arguments(pc_flags UNIX_COMMAND "${step_output}")
step("consumer build (pkg-config)" ${LAUNCHER} ${CXX} -std=c++20 ${CONSUMER_DIR}/main.cpp ${pc_flags}
     -o ${WORK_DIR}/pc-consumer)
# A shared build's libraries: found through the loader path, as a user of a custom prefix sets it.
get_filename_component(lib_dir ${pc_dir} DIRECTORY)
set(ENV{LD_LIBRARY_PATH} "${lib_dir}:$ENV{LD_LIBRARY_PATH}")
step("consumer run (pkg-config)" ${WORK_DIR}/pc-consumer)
check_consumer("pkg-config" "${step_output}")

# 3. A core-only user. The I/O packages are made unfindable (CMAKE_DISABLE_FIND_PACKAGE_<name>):
# a config that asked for them fails to configure. Control first: the full package does fail so.
set(io_packages assimp nlohmann_json TinyGLTF)
set(no_io_packages "")
foreach(package ${io_packages})
  list(APPEND no_io_packages -DCMAKE_DISABLE_FIND_PACKAGE_${package}=ON)
endforeach()
# The names of the I/O libraries and of clod's layers above the core, on a link line or in ldd's list.
set(io_library_regex "assimp|tinygltf|nlohmann|json|clod_mesh_io|clod_scene|clod_export|clod_dynamics")
execute_process(COMMAND ${CMAKE_COMMAND} -S ${CONSUMER_DIR} -B ${WORK_DIR}/full-no-io
  -G ${GENERATOR} -DCMAKE_CXX_COMPILER=${CXX} -DCMAKE_PREFIX_PATH=${prefix}
  -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF ${no_io_packages}
  RESULT_VARIABLE rc OUTPUT_QUIET ERROR_QUIET)
if(rc EQUAL 0)
  message(FATAL_ERROR "control: find_package(clod) (all components) configured with ${io_packages} "
    "disabled, so disabling them proves nothing about the core-only consumer")
endif()
set(core_consumer ${CONSUMER_DIR}/../consumer_core)
set(core_build ${WORK_DIR}/core-build)
step("core consumer configure" ${CMAKE_COMMAND} -S ${core_consumer} -B ${core_build}
     -G ${GENERATOR} -DCMAKE_BUILD_TYPE= -DCMAKE_CXX_COMPILER=${CXX} ${launcher}
     -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF ${no_io_packages})
# The link line CMake made from the exported link interface of clod::core (Ninja's build.ninja
# or the Makefiles' link.txt).
step("core consumer build" ${CMAKE_COMMAND} --build ${core_build})
file(GLOB_RECURSE link_files ${core_build}/build.ninja ${core_build}/link.txt)
set(link_lines "")
foreach(link_file ${link_files})
  file(STRINGS ${link_file} lines REGEX "LINK_LIBRARIES|clod_core_consumer")
  string(APPEND link_lines "${lines}")
endforeach()
if(NOT link_lines MATCHES "clod_narrowphase")
  message(FATAL_ERROR "core consumer: no link line naming clod_narrowphase found in ${link_files}")
endif()
if(link_lines MATCHES "${io_library_regex}")
  message(FATAL_ERROR "core consumer: the link line names ${CMAKE_MATCH_0}:\n${link_lines}")
endif()
step("core consumer run" ${core_build}/clod_core_consumer)
check_consumer("core consumer" "${step_output}")
# The libraries the program loads (a shared build's clod layers and their dependencies).
find_program(LDD ldd)
if(LDD)
  step("ldd core consumer" ${LDD} ${core_build}/clod_core_consumer)
  if(step_output MATCHES "${io_library_regex}")
    message(FATAL_ERROR "core consumer loads ${CMAKE_MATCH_0}:\n${step_output}")
  endif()
  if(EXISTS ${lib_dir}/libclod_narrowphase.so AND NOT step_output MATCHES "libclod_narrowphase")
    message(FATAL_ERROR "shared build, yet ldd does not list libclod_narrowphase:\n${step_output}")
  endif()
endif()
# pkg-config: clod-core.pc. Control: a static build's clod.pc does name Assimp.
step("pkg-config clod" ${PKG_CONFIG} --libs clod)
if(NOT EXISTS ${lib_dir}/libclod_narrowphase.so AND NOT step_output MATCHES "assimp")
  message(FATAL_ERROR "control: a static build's `pkg-config --libs clod` does not name assimp:\n${step_output}")
endif()
step("pkg-config clod-core" ${PKG_CONFIG} --cflags --libs clod-core)
if(step_output MATCHES "${io_library_regex}")
  message(FATAL_ERROR "pkg-config clod-core names ${CMAKE_MATCH_0}:\n${step_output}")
endif()
separate_arguments(pc_flags UNIX_COMMAND "${step_output}")
step("core consumer build (pkg-config)" ${LAUNCHER} ${CXX} -std=c++20 ${CONSUMER_DIR}/main.cpp ${pc_flags}
     -o ${WORK_DIR}/pc-core-consumer)
step("core consumer run (pkg-config)" ${WORK_DIR}/pc-core-consumer)
check_consumer("core consumer (pkg-config)" "${step_output}")

# The other components, configured only: each loads what it needs and no more, and finds only
# its own packages (world: none of the I/O ones; io: Assimp but no JSON or glTF). An unknown
# component is refused.
set(probe_dir ${WORK_DIR}/component-probe)
file(WRITE ${probe_dir}/CMakeLists.txt [=[
cmake_minimum_required(VERSION 3.25)
project(clod_component_probe LANGUAGES CXX)
find_package(clod REQUIRED COMPONENTS ${PROBE_COMPONENT})
foreach(target ${PROBE_PRESENT})
  if(NOT TARGET clod::${target})
    message(FATAL_ERROR "clod::${target} is missing")
  endif()
endforeach()
foreach(target ${PROBE_ABSENT})
  if(TARGET clod::${target})
    message(FATAL_ERROR "clod::${target} was loaded, yet not asked for")
  endif()
endforeach()
]=])
function(probe_component name component present absent)
  execute_process(COMMAND ${CMAKE_COMMAND} -S ${probe_dir} -B ${WORK_DIR}/probe-${name} -G ${GENERATOR}
    -DCMAKE_CXX_COMPILER=${CXX} -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF
    "-DPROBE_COMPONENT=${component}" "-DPROBE_PRESENT=${present}" "-DPROBE_ABSENT=${absent}" ${ARGN}
    RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  set(probe_rc ${rc} PARENT_SCOPE)
  set(probe_output "${out}\n${err}" PARENT_SCOPE)
endfunction()
probe_component(world world "world;core" "io;scene;clod" ${no_io_packages})
if(NOT probe_rc EQUAL 0)
  message(FATAL_ERROR "find_package(clod COMPONENTS world) without the I/O packages:\n${probe_output}")
endif()
probe_component(io io "io;core" "world;scene;clod" -DCMAKE_DISABLE_FIND_PACKAGE_nlohmann_json=ON
  -DCMAKE_DISABLE_FIND_PACKAGE_TinyGLTF=ON)
if(NOT probe_rc EQUAL 0)
  message(FATAL_ERROR "find_package(clod COMPONENTS io) without JSON and glTF:\n${probe_output}")
endif()
probe_component(scene scene "scene;world;io;core;clod" "")
if(NOT probe_rc EQUAL 0)
  message(FATAL_ERROR "find_package(clod COMPONENTS scene):\n${probe_output}")
endif()
probe_component(unknown "core;nope" "core" "")
if(probe_rc EQUAL 0)
  message(FATAL_ERROR "find_package(clod REQUIRED COMPONENTS core nope) configured")
endif()
message(STATUS "components: world, io and scene load what they need; an unknown one is refused")

# 4. The Bullet plug-in, when this build has it: find_package(clod COMPONENTS bullet).
file(GLOB_RECURSE bullet_targets ${prefix}/*/clodBulletTargets.cmake)
if(bullet_targets)
  set(bullet_consumer ${CONSUMER_DIR}/../consumer_bullet)
  step("bullet consumer configure" ${CMAKE_COMMAND} -S ${bullet_consumer} -B ${WORK_DIR}/bullet-build
       -G ${GENERATOR} -DCMAKE_BUILD_TYPE= -DCMAKE_CXX_COMPILER=${CXX} ${launcher}
       -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF)
  step("bullet consumer build" ${CMAKE_COMMAND} --build ${WORK_DIR}/bullet-build)
  step("bullet consumer run" ${WORK_DIR}/bullet-build/clod_bullet_consumer)
  if(NOT step_output MATCHES "cube at z 0\\.(49|50)[0-9]* on the plane, contacts [1-9]")
    message(FATAL_ERROR "bullet consumer: unexpected output:\n${step_output}")
  endif()
  message(STATUS "bullet consumer: ${step_output}")
else()
  message(STATUS "bullet consumer: skipped (this build installs no clod_bullet)")
endif()
