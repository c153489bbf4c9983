# Install rules: `cmake --install build --prefix P` gives
#   P/lib/libkdet.a (or .so), P/include/kdet/*.hpp       the library and its public headers only
#   P/lib/cmake/kdet/kdet{Config,ConfigVersion,Targets}*  find_package(kdet 0.1 CONFIG REQUIRED) -> kdet::kdet
#   P/lib/libkdet_mpi.a, P/lib/cmake/kdet/kdetMpiTargets*, kdet_find_mpi.cmake
#                                                        with MPI: find_package(kdet COMPONENTS mpi) -> kdet::mpi
#   P/bin/kdet, P/share/kdet/python/*.py                  the command and the scripts of `kdet plot`
# The benchmark harness (kdet::scenes), the tests and the private headers of src/ are not installed.
# Components: development (library, headers, package), tool (the command); the Python package installs
# its own component, python, and nothing else (pyproject.toml).
include(CMakePackageConfigHelpers)

set(KDET_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/kdet CACHE STRING "Where the CMake package files go")

# A shared build (BUILD_SHARED_LIBS) gets libkdet.so.0 -> libkdet.so.0.1.0, matching SameMajorVersion below.
set_target_properties(kdet PROPERTIES VERSION ${PROJECT_VERSION} SOVERSION ${PROJECT_VERSION_MAJOR})
install(TARGETS kdet EXPORT kdetTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT development
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT development
  RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT development)
# mpi.hpp only with the library it declares.
set(_kdet_header_exclude)
if(NOT TARGET kdet_mpi)
  set(_kdet_header_exclude PATTERN mpi.hpp EXCLUDE)
endif()
install(DIRECTORY ${PROJECT_SOURCE_DIR}/include/kdet DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} COMPONENT development
        ${_kdet_header_exclude})
install(EXPORT kdetTargets NAMESPACE kdet:: DESTINATION ${KDET_INSTALL_CMAKEDIR} COMPONENT development)
# kdet::mpi, the optional component `mpi`: a targets file of its own, read only when it is asked for,
# so that users of kdet::kdet alone never need MPI.
if(TARGET kdet_mpi)
  set_target_properties(kdet_mpi PROPERTIES VERSION ${PROJECT_VERSION} SOVERSION ${PROJECT_VERSION_MAJOR})
  install(TARGETS kdet_mpi EXPORT kdetMpiTargets
    ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT development
    LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT development
    RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT development)
  install(EXPORT kdetMpiTargets NAMESPACE kdet:: DESTINATION ${KDET_INSTALL_CMAKEDIR} COMPONENT development)
  install(FILES ${CMAKE_CURRENT_LIST_DIR}/find_mpi.cmake RENAME kdet_find_mpi.cmake DESTINATION ${KDET_INSTALL_CMAKEDIR}
    COMPONENT development)
endif()

configure_package_config_file(${CMAKE_CURRENT_LIST_DIR}/kdetConfig.cmake.in ${PROJECT_BINARY_DIR}/kdetConfig.cmake
  INSTALL_DESTINATION ${KDET_INSTALL_CMAKEDIR})
# 0.x releases stay compatible with each other, as the issue asks for find_package(kdet 0.1).
write_basic_package_version_file(${PROJECT_BINARY_DIR}/kdetConfigVersion.cmake COMPATIBILITY SameMajorVersion)
install(FILES ${PROJECT_BINARY_DIR}/kdetConfig.cmake ${PROJECT_BINARY_DIR}/kdetConfigVersion.cmake
  DESTINATION ${KDET_INSTALL_CMAKEDIR} COMPONENT development)

if(TARGET kdet_cli)
  install(TARGETS kdet_cli RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT tool)
  # `kdet plot` finds its scripts beside the installed command (tools/bench_plot.cpp).
  install(FILES ${PROJECT_SOURCE_DIR}/python/kdet_plot.py ${PROJECT_SOURCE_DIR}/python/kdet_csv.py
                ${PROJECT_SOURCE_DIR}/python/kdet_summary.py
          DESTINATION ${CMAKE_INSTALL_DATADIR}/kdet/python COMPONENT tool)
  if(BUILD_SHARED_LIBS)
    set_target_properties(kdet_cli PROPERTIES INSTALL_RPATH "$ORIGIN/../${CMAKE_INSTALL_LIBDIR}")
  endif()
endif()
