# Imported targets for the two libraries octiso links by file name: xxHash ships no CMake package
# on Debian 12, and OpenImageIO's package there points at a missing opencv4 include directory.
# Included by CMakeLists.txt and by the installed octisoConfig.cmake, so the build and every
# consumer of the installed package find the same files. Each function defines its target when
# the library is found and leaves it undefined otherwise; the caller decides whether that is fatal.

# octiso_deps::xxhash: xxhash.h (XXH3 section checksums of the .oct format, compiled into core).
function(octiso_import_xxhash)
  if(TARGET octiso_deps::xxhash)
    return()
  endif()
  # Header only: validate.cpp compiles XXH3 in (XXH_INLINE_ALL), so nothing links libxxhash.
  find_path(OCTISO_XXHASH_INCLUDE_DIR xxhash.h)
  if(OCTISO_XXHASH_INCLUDE_DIR)
    add_library(octiso_deps::xxhash INTERFACE IMPORTED)
    set_target_properties(octiso_deps::xxhash PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${OCTISO_XXHASH_INCLUDE_DIR}")
  endif()
endfunction()

# octiso_deps::OpenImageIO: libOpenImageIO + libOpenImageIO_Util (every image file; io).
function(octiso_import_openimageio)
  if(TARGET octiso_deps::OpenImageIO)
    return()
  endif()
  find_path(OCTISO_OIIO_INCLUDE_DIR OpenImageIO/imageio.h)
  find_library(OCTISO_OIIO_LIBRARY OpenImageIO)
  find_library(OCTISO_OIIO_UTIL_LIBRARY OpenImageIO_Util)
  if(OCTISO_OIIO_INCLUDE_DIR AND OCTISO_OIIO_LIBRARY AND OCTISO_OIIO_UTIL_LIBRARY)
    add_library(octiso_deps::OpenImageIO UNKNOWN IMPORTED)
    set_target_properties(octiso_deps::OpenImageIO PROPERTIES IMPORTED_LOCATION "${OCTISO_OIIO_LIBRARY}"
                          INTERFACE_INCLUDE_DIRECTORIES "${OCTISO_OIIO_INCLUDE_DIR}"
                          INTERFACE_LINK_LIBRARIES "${OCTISO_OIIO_UTIL_LIBRARY}")
  endif()
endfunction()
