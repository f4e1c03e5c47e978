# world_compare: frame time of a whole scene (the 200-body bin) per contact model and budget, with
# Bullet (btDiscreteDynamicsWorld, GImpact and convex-hull shapes) as the peer in the same run.
# A plain program, not a Google Benchmark one: it reports per-frame distributions of one long
# simulation (see the top of world_compare.cpp). Bullet is optional (cmake/ClodDependencies.cmake).
add_executable(world_compare ${CMAKE_CURRENT_LIST_DIR}/world_compare.cpp)
target_link_libraries(world_compare PRIVATE clod::clod)
target_compile_definitions(world_compare PRIVATE CLOD_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
                                                 CLOD_BINARY_DIR="${PROJECT_BINARY_DIR}")
clod_target_defaults(world_compare)
clod_bench_link_bullet(world_compare "Bullet (GImpact and convex hulls)")
