# The version check of find_package(shapecorr <version> CONFIG).
#
# The version is read from the pkg-config file `cargo cinstall` writes beside the library, so
# it is never a second copy of Cargo.toml's. Before 1.0 a minor version may break the API
# (Cargo's rule), so 0.x.y satisfies only requests for 0.x.

get_filename_component(_shapecorr_prefix "${CMAKE_CURRENT_LIST_DIR}/../../.." ABSOLUTE)
file(GLOB _shapecorr_pc
    "${_shapecorr_prefix}/lib/pkgconfig/shapecorr.pc"
    "${_shapecorr_prefix}/lib64/pkgconfig/shapecorr.pc"
    "${_shapecorr_prefix}/lib/*/pkgconfig/shapecorr.pc")
set(PACKAGE_VERSION "")
if(_shapecorr_pc)
    list(GET _shapecorr_pc 0 _shapecorr_pc)
    file(STRINGS "${_shapecorr_pc}" _shapecorr_line REGEX "^Version: ")
    string(REGEX REPLACE "^Version: *([0-9.]+).*" "\\1" PACKAGE_VERSION "${_shapecorr_line}")
endif()

if(PACKAGE_VERSION STREQUAL "")
    set(PACKAGE_VERSION_UNSUITABLE TRUE)
elseif(NOT PACKAGE_FIND_VERSION)
    set(PACKAGE_VERSION_COMPATIBLE TRUE)
else()
    string(REPLACE "." ";" _shapecorr_parts "${PACKAGE_VERSION}")
    list(GET _shapecorr_parts 0 _shapecorr_major)
    list(GET _shapecorr_parts 1 _shapecorr_minor)
    if(PACKAGE_VERSION VERSION_LESS PACKAGE_FIND_VERSION
       OR NOT _shapecorr_major EQUAL PACKAGE_FIND_VERSION_MAJOR
       OR (_shapecorr_major EQUAL 0 AND NOT _shapecorr_minor EQUAL PACKAGE_FIND_VERSION_MINOR))
        set(PACKAGE_VERSION_COMPATIBLE FALSE)
    else()
        set(PACKAGE_VERSION_COMPATIBLE TRUE)
        if(PACKAGE_VERSION VERSION_EQUAL PACKAGE_FIND_VERSION)
            set(PACKAGE_VERSION_EXACT TRUE)
        endif()
    endif()
endif()
unset(_shapecorr_prefix)
unset(_shapecorr_pc)
