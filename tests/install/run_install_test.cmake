# Installs the build tree into WORK_DIR/prefix, then configures, builds and runs an outside project
# (tests/install/consumer) that finds the package with find_package(fesd) and links fesd::fesd.
file(REMOVE_RECURSE ${WORK_DIR})
execute_process(COMMAND ${CMAKE_COMMAND} --install ${BINARY_DIR} --prefix ${WORK_DIR}/prefix
                RESULT_VARIABLE rc OUTPUT_QUIET)
if(rc)
  message(FATAL_ERROR "cmake --install failed (${rc})")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} -S ${SOURCE_DIR}/tests/install/consumer -B ${WORK_DIR}/build
                        -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix -DCMAKE_BUILD_TYPE=Release
                RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "configuring the consumer project failed (${rc})")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} --build ${WORK_DIR}/build RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "building the consumer project failed (${rc})")
endif()
execute_process(COMMAND ${WORK_DIR}/build/consumer RESULT_VARIABLE rc OUTPUT_VARIABLE out)
message(STATUS "${out}")
if(rc)
  message(FATAL_ERROR "the consumer program failed (${rc})")
endif()

# The stepping API in a control loop (examples/cpp/stepper_loop.cpp, docs/active-set.md).
execute_process(COMMAND ${WORK_DIR}/build/stepper_loop RESULT_VARIABLE rc OUTPUT_VARIABLE out)
message(STATUS "${out}")
if(rc)
  message(FATAL_ERROR "the stepper_loop program failed (${rc})")
endif()

# The Python package (docs/python.md): installed under PYTHON_DIR (relative to the prefix), it
# imports from there with the build tree out of reach and loads the installed libfesd (RUNPATH).
if(PYTHON AND PYTHON_DIR AND NOT IS_ABSOLUTE "${PYTHON_DIR}")
  set(site ${WORK_DIR}/prefix/${PYTHON_DIR})
  set(check [=[
import sys, fesd
prefix = sys.argv[1]
assert fesd.__file__.startswith(prefix), fesd.__file__
libs = [l.split()[-1] for l in open("/proc/self/maps") if "libfesd.so" in l]
assert libs and all(l.startswith(prefix) for l in libs), libs
r = fesd.simulate(sys.argv[2], N_sim=40, error_estimate=False)
assert r.success and abs(r.switch_times[0] - 1) < 1e-6, r.brief_report()
print("python: import fesd from", fesd.__file__, "-", r.brief_report())
]=])
  execute_process(COMMAND ${CMAKE_COMMAND} -E env PYTHONPATH=${site} PYTHONNOUSERSITE=1
                          ${PYTHON} -c "${check}" ${WORK_DIR}/prefix
                          ${SOURCE_DIR}/examples/oscillator.toml
                  WORKING_DIRECTORY ${WORK_DIR} RESULT_VARIABLE rc OUTPUT_VARIABLE out
                  ERROR_VARIABLE err)
  message(STATUS "${out}")
  if(rc)
    message(FATAL_ERROR "the installed Python package failed (${rc}): ${err}")
  endif()
endif()
