# ctest package/install_and_consume: installs this build tree into a fresh prefix, then builds
# and runs tests/package/consumer twice from outside the tree -- once through
# find_package(clod) and once through `pkg-config --cflags --libs clod` -- the two ways the
# README tells users to adopt clod. Nothing is downloaded; it fails on the first step that does.
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

# 3. The Bullet plug-in, when this build has it: find_package(clod COMPONENTS bullet).
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
