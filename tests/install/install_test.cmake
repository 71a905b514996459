# The install test: cmake --install into a temporary prefix, move the
# prefix elsewhere (an install must not remember where it was made), then
# build a library user's program against it with find_package and with
# pkg-config, and run both.  Run by ctest as
#   cmake -DBUILD_DIR=.. -DWORK=.. -DCONSUMER=.. -DLIBDIR=.. -DDATADIR=..
#         -DVERSION=.. -DCC=.. -DCFLAGS=.. -P install_test.cmake
foreach(v BUILD_DIR WORK CONSUMER LIBDIR DATADIR VERSION CC)
  if(NOT DEFINED ${v})
    message(FATAL_ERROR "install_test.cmake: -D${v}=... missing")
  endif()
endforeach()

function(run what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${what} failed (${rc}):\n${ARGN}\n${out}\n${err}")
  endif()
  set(run_out "${out}" PARENT_SCOPE)
endfunction()

file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
set(made ${WORK}/made)
set(moved ${WORK}/moved)
run("cmake --install" ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${made})
file(RENAME ${made} ${moved})

foreach(f bin/lenstrace bin/lensrender bin/pov_compare include/lensprim.h
          ${LIBDIR}/liblensprim.a
          ${LIBDIR}/cmake/lensprim/lensprimConfig.cmake
          ${LIBDIR}/cmake/lensprim/lensprimConfigVersion.cmake
          ${LIBDIR}/cmake/lensprim/lensprimTargets.cmake
          ${LIBDIR}/pkgconfig/lensprim.pc
          ${DATADIR}/lensprim/lens.inc ${DATADIR}/lensprim/scenes/default.scene)
  if(NOT EXISTS ${moved}/${f})
    message(FATAL_ERROR "not installed: ${f}")
  endif()
endforeach()
run("installed lenstrace --version" ${moved}/bin/lenstrace --version)
if(NOT run_out MATCHES "${VERSION}")
  message(FATAL_ERROR "installed lenstrace --version says '${run_out}', want ${VERSION}")
endif()

# 1. find_package(lensprim) with CMAKE_PREFIX_PATH = the moved prefix.
run("configure the consumer" ${CMAKE_COMMAND} -S ${CONSUMER} -B ${WORK}/consumer
    -DCMAKE_PREFIX_PATH=${moved} -DCMAKE_C_COMPILER=${CC} "-DCMAKE_C_FLAGS=${CFLAGS}"
    -DCMAKE_BUILD_TYPE=Release)
run("build the consumer" ${CMAKE_COMMAND} --build ${WORK}/consumer)
run("run the find_package consumer" ${WORK}/consumer/consumer ${VERSION})
message(STATUS "find_package: ${run_out}")

# 2. pkg-config, with the .pc found in the moved prefix.
find_program(PKG_CONFIG NAMES pkg-config pkgconf REQUIRED)
set(ENV{PKG_CONFIG_PATH} ${moved}/${LIBDIR}/pkgconfig)
run("pkg-config --cflags" ${PKG_CONFIG} --cflags lensprim)
string(STRIP "${run_out}" pc_cflags)
run("pkg-config --libs" ${PKG_CONFIG} --libs lensprim)
string(STRIP "${run_out}" pc_libs)
get_filename_component(moved_real ${moved} REALPATH)
if(NOT pc_cflags MATCHES "^-I(${moved}|${moved_real})/"
   AND NOT pc_cflags STREQUAL "")
  message(FATAL_ERROR "pkg-config --cflags: '${pc_cflags}' does not point into ${moved}")
endif()
if(NOT pc_libs MATCHES "-L(${moved}|${moved_real})/")
  message(FATAL_ERROR "pkg-config --libs: '${pc_libs}' does not point into ${moved}")
endif()
separate_arguments(cflags_list UNIX_COMMAND "${CFLAGS} ${pc_cflags}")
separate_arguments(libs_list UNIX_COMMAND "${pc_libs}")
run("compile the consumer with pkg-config" ${CC} ${cflags_list} ${CONSUMER}/consumer.c
    -o ${WORK}/consumer_pc ${libs_list})
run("run the pkg-config consumer" ${WORK}/consumer_pc ${VERSION})
message(STATUS "pkg-config: ${run_out}")

# 3. The installed pov_compare finds lens.inc for a scene in a folder of
# its own: in a -L directory first, else in the installed share directory
# (before the build's source tree).  lens.inc is copied into the output
# before POV-Ray runs, so a missing POV-Ray (exit 1) still shows which
# lens.inc was found; a --lens-inc that does not exist exits 2.
function(pov_compare_run want_rc out)
  execute_process(COMMAND ${moved}/bin/pov_compare ${WORK}/user/default.scene --out ${out}
                          --width 8 --height 6 --povray ${WORK}/no-povray --quiet ${ARGN}
                  RESULT_VARIABLE rc ERROR_VARIABLE err)
  if(NOT rc EQUAL want_rc)
    message(FATAL_ERROR "pov_compare ${ARGN}: exit ${rc}, want ${want_rc}: ${err}")
  endif()
endfunction()
file(COPY ${moved}/${DATADIR}/lensprim/scenes/default.scene DESTINATION ${WORK}/user)
file(APPEND ${moved}/${DATADIR}/lensprim/lens.inc "// installed copy\n")
file(MAKE_DIRECTORY ${WORK}/lib)
file(READ ${moved}/${DATADIR}/lensprim/lens.inc inc)
file(WRITE ${WORK}/lib/lens.inc "${inc}// library path copy\n")
pov_compare_run(1 ${WORK}/pc_share)
file(READ ${WORK}/pc_share/lens.inc got)
if(NOT got MATCHES "// installed copy\n$")
  message(FATAL_ERROR "pov_compare did not take lens.inc from the installed share directory")
endif()
pov_compare_run(1 ${WORK}/pc_lib +L${WORK}/lib)
file(READ ${WORK}/pc_lib/lens.inc got)
if(NOT got MATCHES "// library path copy\n$")
  message(FATAL_ERROR "pov_compare +L did not take lens.inc from the library path")
endif()
pov_compare_run(2 ${WORK}/pc_bad --lens-inc ${WORK}/no-such.inc)
message(STATUS "pov_compare: lens.inc from -L, then share/lensprim; a missing one exits 2")
