# find_package(shapecorr CONFIG) for an installed shapecorr: the imported target
# shapecorr::shapecorr (the shared library and its header folder).
#
# `cargo cinstall` puts this file in <prefix>/share/cmake/shapecorr. It finds the library and
# the header relative to that prefix, so an installed tree can be staged with DESTDIR or moved.
# The library folder is lib, lib64 or lib/<multiarch>, whichever `--libdir` chose.

get_filename_component(_shapecorr_prefix "${CMAKE_CURRENT_LIST_DIR}/../../.." ABSOLUTE)

# Searched afresh each time (not kept in the cache): the answer belongs to this prefix.
find_path(_shapecorr_include_dir shapecorr.h
    PATHS "${_shapecorr_prefix}/include" NO_DEFAULT_PATH)
find_library(_shapecorr_library NAMES shapecorr
    PATHS "${_shapecorr_prefix}/lib" "${_shapecorr_prefix}/lib64"
    PATH_SUFFIXES "" "${CMAKE_LIBRARY_ARCHITECTURE}"
    NO_DEFAULT_PATH)
set(shapecorr_INCLUDE_DIR "${_shapecorr_include_dir}")
set(shapecorr_LIBRARY "${_shapecorr_library}")
unset(_shapecorr_include_dir CACHE)
unset(_shapecorr_library CACHE)

if(NOT shapecorr_INCLUDE_DIR OR NOT shapecorr_LIBRARY)
    set(shapecorr_FOUND FALSE)
    set(shapecorr_NOT_FOUND_MESSAGE
        "shapecorr: no shapecorr.h or libshapecorr under ${_shapecorr_prefix} (reinstall with `cargo cinstall`)")
    return()
endif()

if(NOT TARGET shapecorr::shapecorr)
    add_library(shapecorr::shapecorr SHARED IMPORTED)
    set_target_properties(shapecorr::shapecorr PROPERTIES
        IMPORTED_LOCATION "${shapecorr_LIBRARY}"
        INTERFACE_INCLUDE_DIRECTORIES "${shapecorr_INCLUDE_DIR}")
endif()
set(shapecorr_LIBRARIES shapecorr::shapecorr)
set(shapecorr_INCLUDE_DIRS "${shapecorr_INCLUDE_DIR}")
unset(_shapecorr_prefix)
