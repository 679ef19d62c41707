# ctest python_install: install the `python` component into PREFIX and import
# the module from PREFIX/SITE_DIR with nothing else on PYTHONPATH.
file(REMOVE_RECURSE ${PREFIX})
execute_process(COMMAND ${CMAKE_COMMAND} --install ${BUILD_DIR} --component python --prefix ${PREFIX}
                RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "cmake --install --component python failed (${rc})")
endif()
set(ENV{PYTHONPATH} ${PREFIX}/${SITE_DIR})
execute_process(
  COMMAND ${PYTHON} -c "import zwang, sys; m = zwang.load_urdf(sys.argv[1], tip='tool0'); r = zwang.solve(m, m.workspace(), [0.0]*7); print(zwang.__file__, m.dof, r.qdd.shape)" ${MODEL}
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
message(STATUS "${out}${err}")
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "import from the installed prefix failed")
endif()
string(FIND "${out}" "${PREFIX}/${SITE_DIR}/zwang" at)
if(at EQUAL -1)
  message(FATAL_ERROR "the module was not imported from ${PREFIX}/${SITE_DIR}")
endif()
