# CHOLMOD and UMFPACK from SuiteSparse (their supernodal and LU modules are GPL) as the imported
# target remora::suitesparse. Debian 12's libsuitesparse-dev ships no CMake package, so the header
# and the three libraries are found by find_path/find_library on the default search paths (set
# SUITESPARSE_INCLUDE_DIR, CHOLMOD_LIBRARY, UMFPACK_LIBRARY and SUITESPARSECONFIG_LIBRARY to point
# elsewhere). Included by Remora's build and by the installed remoraConfig.cmake; when something
# is missing, remora::suitesparse is not defined and REMORA_SUITESPARSE_MISSING names what.
include_guard(GLOBAL)

find_path(SUITESPARSE_INCLUDE_DIR cholmod.h PATH_SUFFIXES suitesparse)
find_library(CHOLMOD_LIBRARY cholmod)
find_library(UMFPACK_LIBRARY umfpack)
find_library(SUITESPARSECONFIG_LIBRARY suitesparseconfig)

set(REMORA_SUITESPARSE_MISSING "")
foreach(_remora_var SUITESPARSE_INCLUDE_DIR CHOLMOD_LIBRARY UMFPACK_LIBRARY SUITESPARSECONFIG_LIBRARY)
  if(NOT ${_remora_var})
    list(APPEND REMORA_SUITESPARSE_MISSING ${_remora_var})
  endif()
endforeach()
unset(_remora_var)

if(NOT REMORA_SUITESPARSE_MISSING AND NOT TARGET remora::suitesparse)
  add_library(remora::suitesparse INTERFACE IMPORTED)
  set_target_properties(remora::suitesparse PROPERTIES
    INTERFACE_INCLUDE_DIRECTORIES "${SUITESPARSE_INCLUDE_DIR}"
    INTERFACE_LINK_LIBRARIES "${CHOLMOD_LIBRARY};${UMFPACK_LIBRARY};${SUITESPARSECONFIG_LIBRARY}")
endif()
