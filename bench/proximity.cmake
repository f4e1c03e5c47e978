# Peer comparisons for bench_proximity: CGAL's AABB_tree and Embree's point queries, compiled in
# only when their packages were found (cmake/ClodDependencies.cmake). Neither is ever required.
if(TARGET bench_proximity)
  if(TARGET CGAL::CGAL)
    target_link_libraries(bench_proximity PRIVATE CGAL::CGAL)
    target_compile_definitions(bench_proximity PRIVATE CLOD_BENCH_HAVE_CGAL)
  endif()
  if(TARGET embree)
    target_link_libraries(bench_proximity PRIVATE embree)
    target_compile_definitions(bench_proximity PRIVATE CLOD_BENCH_HAVE_EMBREE)
  endif()
endif()
