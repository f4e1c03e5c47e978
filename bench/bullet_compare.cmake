# bullet_compare: issue 17's box scenes (degradation.h) in clod's world at each budget, beside Bullet
# 3.24 with the same boxes as btGImpactMeshShape and beside Bullet with clod as its collider
# (clod_bullet, engines/bullet); and the 200-body bin, GImpact vs clod in Bullet (issue 19).
# Needs the plug-in (Bullet found, CLOD_BUILD_ENGINES).
if(TARGET clod_bullet)
  add_executable(bullet_compare ${CMAKE_CURRENT_LIST_DIR}/bullet_compare.cpp)
  target_link_libraries(bullet_compare PRIVATE clod::clod clod_bullet)
  target_compile_definitions(bullet_compare PRIVATE CLOD_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
                                                    CLOD_BINARY_DIR="${PROJECT_BINARY_DIR}")
  clod_target_defaults(bullet_compare)
else()
  message(STATUS "bullet_compare: clod_bullet not built (Bullet not found or CLOD_BUILD_ENGINES=OFF), skipped")
endif()
