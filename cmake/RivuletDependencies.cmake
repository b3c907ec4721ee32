# Every dependency is a Debian 12 package; .ci/install-deps installs them.
find_package(TBB CONFIG REQUIRED)
find_package(Eigen3 CONFIG REQUIRED)
find_package(CLI11 CONFIG REQUIRED)
find_package(nlohmann_json CONFIG REQUIRED)
find_package(fmt CONFIG REQUIRED)
find_package(PNG REQUIRED)
find_package(PkgConfig REQUIRED)
# Link OSMesa alone: with libGL (glvnd) also on the line, GL calls silently draw nothing (shared/PLATFORM.md).
pkg_check_modules(OSMESA REQUIRED IMPORTED_TARGET osmesa)
pkg_check_modules(XXHASH REQUIRED IMPORTED_TARGET libxxhash)
# FFmpeg's libraries encode `run --video` (systems/render/video_writer.cpp, docs/video.md).
pkg_check_modules(FFMPEG REQUIRED IMPORTED_TARGET libavcodec libavformat libavutil libswscale)
# Assimp reads the meshes diffuse objects are voxelized from (systems/io/assimp_mesh.cpp).
pkg_check_modules(ASSIMP REQUIRED IMPORTED_TARGET assimp)
# OpenVDB writes density volumes as .vdb files (systems/io/vdb_writer.cpp). Debian ships FindOpenVDB.cmake
# (which also wants Boost.Iostreams) in a folder of its own, beside a FindTBB.cmake of its own: that folder
# is on the module path only while OpenVDB is looked up, so no other package is found differently.
find_path(RIVULET_OPENVDB_MODULE_DIR FindOpenVDB.cmake
          PATHS /usr/lib/${CMAKE_LIBRARY_ARCHITECTURE}/cmake/OpenVDB /usr/lib/cmake/OpenVDB NO_DEFAULT_PATH)
if(NOT RIVULET_OPENVDB_MODULE_DIR)
  message(FATAL_ERROR "FindOpenVDB.cmake not found: install libopenvdb-dev (.ci/install-deps)")
endif()
set(RIVULET_MODULE_PATH ${CMAKE_MODULE_PATH})
list(APPEND CMAKE_MODULE_PATH ${RIVULET_OPENVDB_MODULE_DIR})
find_package(OpenVDB REQUIRED)
set(CMAKE_MODULE_PATH ${RIVULET_MODULE_PATH})
# Open MPI (libopenmpi-dev) for `mpirun -n K rivulet mesh` (runtime/cluster, docs/cluster.md). Without it the
# command line is the same, one process.
if(RIVULET_MPI)
  find_package(MPI COMPONENTS C)
  if(NOT MPI_C_FOUND)
    message(WARNING "MPI not found (install libopenmpi-dev): rivulet mesh is built without MPI")
    set(RIVULET_MPI OFF)
  endif()
endif()
if(RIVULET_BUILD_TESTS)
  find_package(GTest CONFIG REQUIRED)
endif()
if(RIVULET_BUILD_PERF)
  find_package(benchmark CONFIG REQUIRED)
endif()
