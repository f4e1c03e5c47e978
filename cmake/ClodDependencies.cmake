# Every third-party dependency of clod, found in one place. All come from Debian packages.
find_package(Eigen3 3.4 REQUIRED NO_MODULE)
find_package(TBB REQUIRED)
find_package(assimp REQUIRED)
find_package(nlohmann_json 3.10 REQUIRED)
find_package(CLI11 REQUIRED)
find_package(Qhull REQUIRED)   # Delaunay tetrahedralisation for the medial-axis sphere-tree builder
find_package(Threads REQUIRED)
find_package(PkgConfig REQUIRED)
pkg_check_modules(XXHASH REQUIRED IMPORTED_TARGET libxxhash)  # section checksums of the bake file (XXH3-64)
find_package(TinyGLTF REQUIRED)  # scene.glb export (src/export)

# MuJoCo (Debian's libmujoco-dev 2.2.2) for the clod_mujoco plug-in (engines/mujoco); optional.
if(CLOD_WITH_MUJOCO AND CLOD_BUILD_ENGINES AND NOT CLOD_SANITIZE)
  find_package(mujoco 2.2 QUIET)
endif()
if(CLOD_BUILD_TESTS)
  find_package(GTest REQUIRED)
endif()
if(CLOD_BUILD_ENGINES OR CLOD_BUILD_BENCHMARKS)
  # Bullet 3.24 (libbullet-dev): the clod_bullet plug-in (engines/bullet) and the benchmarks' peer.
  # Optional: without it the plug-in, its tests and the Bullet rows are skipped.
  find_package(Bullet QUIET)
endif()
if(CLOD_BUILD_BENCHMARKS)
  find_package(benchmark REQUIRED)
  # Peers for side-by-side comparisons; each one is optional.
  find_package(CGAL QUIET)
  find_package(embree 3 QUIET)
  find_package(fcl QUIET)
  find_package(OpenVDB QUIET PATHS /usr/lib/x86_64-linux-gnu/cmake/OpenVDB)
endif()
