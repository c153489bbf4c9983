# kdet_find_mpi([QUIET|REQUIRED]): MPI for kdet::mpi, which calls MPI's C API alone. The MPI-2 C++
# bindings are neither compiled in (MPI_CXX_SKIP_MPICXX) nor linked (their library is dropped from
# MPI::MPI_CXX), so a program built against one MPI library runs under another of the same ABI (Open
# MPI 5 no longer has them). Used by the build and by the installed package's config.
macro(kdet_find_mpi)
  set(MPI_CXX_SKIP_MPICXX ON)
  find_package(MPI ${ARGN} COMPONENTS CXX)
  if(TARGET MPI::MPI_CXX)
    get_target_property(_kdet_mpi_libraries MPI::MPI_CXX INTERFACE_LINK_LIBRARIES)
    if(_kdet_mpi_libraries)
      list(FILTER _kdet_mpi_libraries EXCLUDE REGEX "mpi_?cxx")
      set_target_properties(MPI::MPI_CXX PROPERTIES INTERFACE_LINK_LIBRARIES "${_kdet_mpi_libraries}")
    endif()
  endif()
endmacro()
