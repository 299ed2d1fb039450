# Installs the build into a fresh prefix, builds tests/package/consumer against it with
# find_package(loci), and runs it on the bundled sample: the CMake package as users get it.
# Run with cmake -DBUILD_DIR=... -DSOURCE_DIR=... -DWORK_DIR=... -DCXX=... -DLAYER=... -P.
foreach(v BUILD_DIR SOURCE_DIR WORK_DIR CXX LAYER GENERATOR)
  if(NOT DEFINED ${v})
    message(FATAL_ERROR "package_test.cmake needs -D${v}=...")
  endif()
endforeach()
file(REMOVE_RECURSE "${WORK_DIR}")
function(run what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${what} failed (${rc}):\n${out}")
  endif()
  message(STATUS "${what}: done")
  set(last_output "${out}" PARENT_SCOPE)
endfunction()
run("install" "${CMAKE_COMMAND}" --install "${BUILD_DIR}" --prefix "${WORK_DIR}/prefix")
# The installed command: loci answers a query its sidecar serves by itself, and hands the rest
# (here, indexing) to loci-full where it is installed.
run("index with the installed loci" "${WORK_DIR}/prefix/bin/loci" index -q "${LAYER}"
    -o "${WORK_DIR}/sample.loci")
# The query is answered by loci alone: loci-full is moved aside for it.
file(RENAME "${WORK_DIR}/prefix/libexec/loci/loci-full" "${WORK_DIR}/loci-full.aside")
run("query with the installed loci" "${WORK_DIR}/prefix/bin/loci" query "${LAYER}"
    --index "${WORK_DIR}/sample.loci" --nearest 10,56 -k 2)
file(RENAME "${WORK_DIR}/loci-full.aside" "${WORK_DIR}/prefix/libexec/loci/loci-full")
if(NOT last_output MATCHES "^[0-9]+\n[0-9]+\n$")
  message(FATAL_ERROR "the installed loci answered:\n${last_output}")
endif()
run("configure the consumer" "${CMAKE_COMMAND}" -S "${SOURCE_DIR}" -B "${WORK_DIR}/build"
    -G "${GENERATOR}" -DCMAKE_BUILD_TYPE=Release "-DCMAKE_CXX_COMPILER=${CXX}"
    "-DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix")
run("build the consumer" "${CMAKE_COMMAND}" --build "${WORK_DIR}/build")
run("run the consumer" "${WORK_DIR}/build/loci_consumer" "${LAYER}")
message(STATUS "${last_output}")
# The header-only index alone, with GDAL and SQLite hidden from find_package.
run("configure the index-only consumer" "${CMAKE_COMMAND}" -S "${SOURCE_DIR}/../index_only"
    -B "${WORK_DIR}/build-index" -G "${GENERATOR}" -DCMAKE_BUILD_TYPE=Release
    "-DCMAKE_CXX_COMPILER=${CXX}" "-DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix"
    -DCMAKE_DISABLE_FIND_PACKAGE_GDAL=ON -DCMAKE_DISABLE_FIND_PACKAGE_SQLite3=ON)
run("build the index-only consumer" "${CMAKE_COMMAND}" --build "${WORK_DIR}/build-index")
run("run the index-only consumer" "${WORK_DIR}/build-index/loci_index_only")
# Clang too, where the machine has it: its warnings are not GCC's.
find_program(CLANGXX clang++)
if(CLANGXX)
  run("configure the consumer with clang++" "${CMAKE_COMMAND}" -S "${SOURCE_DIR}"
      -B "${WORK_DIR}/build-clang" -G "${GENERATOR}" -DCMAKE_BUILD_TYPE=Release
      "-DCMAKE_CXX_COMPILER=${CLANGXX}" "-DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix")
  run("build the consumer with clang++" "${CMAKE_COMMAND}" --build "${WORK_DIR}/build-clang")
  run("run the consumer built with clang++" "${WORK_DIR}/build-clang/loci_consumer" "${LAYER}")
endif()
