# The ConsumerProject test (cmake -P): installs the octiso build tree OCTISO_BINARY_DIR into
# WORK_DIR/prefix, runs the installed tools' --version, then configures, builds and runs this
# directory's consumer project against that prefix. Fails on the first step that fails.
foreach(var OCTISO_BINARY_DIR CONSUMER_SOURCE_DIR WORK_DIR CXX_COMPILER BUILD_TYPE OCTISO_VERSION)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "run_consumer_test.cmake needs -D${var}=...")
  endif()
endforeach()
set(prefix ${WORK_DIR}/prefix)
file(REMOVE_RECURSE ${WORK_DIR})

# 1. Install, as a user would.
execute_process(COMMAND ${CMAKE_COMMAND} --install ${OCTISO_BINARY_DIR} --prefix ${prefix}
                OUTPUT_QUIET COMMAND_ERROR_IS_FATAL ANY)
foreach(file include/octiso/render.h include/octiso/version.h lib/cmake/octiso/octisoConfig.cmake
             lib/cmake/octiso/octisoConfigVersion.cmake bin/octiso-render)
  if(NOT EXISTS ${prefix}/${file})
    message(FATAL_ERROR "the install left out ${file}")
  endif()
endforeach()

# 2. The installed tools run and say their version.
foreach(tool octiso-convert octiso-info octiso-render)
  execute_process(COMMAND ${prefix}/bin/${tool} --version OUTPUT_VARIABLE out COMMAND_ERROR_IS_FATAL ANY)
  if(NOT out STREQUAL "${tool} ${OCTISO_VERSION}\n")
    message(FATAL_ERROR "${tool} --version printed '${out}', expected '${tool} ${OCTISO_VERSION}'")
  endif()
endforeach()

# 2b. The installed renderer writes an image: OpenImageIO comes from the module the install put
#     under lib/octiso (found through the tool's RUNPATH, $ORIGIN/../lib/octiso), not the build tree.
execute_process(COMMAND ${prefix}/bin/octiso-convert --synthetic plume:24 -o ${WORK_DIR}/plume.oct
                OUTPUT_QUIET COMMAND_ERROR_IS_FATAL ANY)
execute_process(COMMAND ${prefix}/bin/octiso-render ${WORK_DIR}/plume.oct --iso 40.5 --size 32x32 -o ${WORK_DIR}/tool.png
                OUTPUT_QUIET ERROR_QUIET COMMAND_ERROR_IS_FATAL ANY)
if(NOT EXISTS ${WORK_DIR}/tool.png)
  message(FATAL_ERROR "the installed octiso-render wrote no ${WORK_DIR}/tool.png")
endif()

# 3. Configure and build the consumer against the prefix only (no package registry, no source tree).
set(launcher)
if(CXX_COMPILER_LAUNCHER)
  set(launcher -DCMAKE_CXX_COMPILER_LAUNCHER=${CXX_COMPILER_LAUNCHER})
endif()
execute_process(COMMAND ${CMAKE_COMMAND} -S ${CONSUMER_SOURCE_DIR} -B ${WORK_DIR}/build
                        -DCMAKE_BUILD_TYPE=${BUILD_TYPE} -DCMAKE_CXX_COMPILER=${CXX_COMPILER} ${launcher}
                        -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF
                COMMAND_ERROR_IS_FATAL ANY)
execute_process(COMMAND ${CMAKE_COMMAND} --build ${WORK_DIR}/build COMMAND_ERROR_IS_FATAL ANY)

# 4. Each builds an octree, renders a frame and exits 0 only if the frame hit the surface; the io
#    one also writes the frame as a PNG and its field as .vti, read back (both modules installed).
execute_process(COMMAND ${WORK_DIR}/build/octiso_consumer COMMAND_ERROR_IS_FATAL ANY)
execute_process(COMMAND ${WORK_DIR}/build/octiso_consumer_io ${WORK_DIR}/frame.png COMMAND_ERROR_IS_FATAL ANY)
foreach(f frame.png frame.png.vti)
  if(NOT EXISTS ${WORK_DIR}/${f})
    message(FATAL_ERROR "octiso_consumer_io wrote no ${WORK_DIR}/${f}")
  endif()
endforeach()
