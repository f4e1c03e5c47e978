# OpenVDB peer for bench_contact_tree (optional). Debian's FindOpenVDB module insists on the
# Boost.Iostreams development package, which a plain libopenvdb-dev install lacks, so the
# library and headers are located directly; the shared library carries its own dependencies.
find_path(CLOD_OPENVDB_INCLUDE_DIR openvdb/openvdb.h)
find_library(CLOD_OPENVDB_LIBRARY openvdb)
find_library(CLOD_IMATH_LIBRARY NAMES Imath-3_1 Imath)  # OpenVDB's half type lives in its headers' API
if(TARGET bench_contact_tree AND CLOD_OPENVDB_INCLUDE_DIR AND CLOD_OPENVDB_LIBRARY)
  target_include_directories(bench_contact_tree SYSTEM PRIVATE ${CLOD_OPENVDB_INCLUDE_DIR})
  target_link_libraries(bench_contact_tree PRIVATE ${CLOD_OPENVDB_LIBRARY} TBB::tbb)
  if(CLOD_IMATH_LIBRARY)
    target_link_libraries(bench_contact_tree PRIVATE ${CLOD_IMATH_LIBRARY})
  endif()
  target_compile_definitions(bench_contact_tree PRIVATE CLOD_BENCH_HAVE_OPENVDB=1)
  message(STATUS "bench_contact_tree: comparing with OpenVDB (${CLOD_OPENVDB_LIBRARY})")
elseif(TARGET bench_contact_tree)
  message(STATUS "bench_contact_tree: OpenVDB not found, peer comparison skipped")
endif()
