# ctest script: install the build into a fresh prefix, then configure, build and run
# examples/consumer against it; with the Python bindings, import the installed package and
# relocalize with it. Variables: BUILD_DIR, SOURCE_DIR, WORK_DIR, GENERATOR, and PYTHON and
# PYTHON_DIR (the install folder under the prefix) when the bindings are built.
file(REMOVE_RECURSE "${WORK_DIR}")
function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE result OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT result EQUAL 0)
    message(FATAL_ERROR "failed (${result}): ${ARGN}\n${out}\n${err}")
  endif()
  message("${out}")
endfunction()
run(${CMAKE_COMMAND} --install "${BUILD_DIR}" --prefix "${WORK_DIR}/prefix")
run(${CMAKE_COMMAND} -S "${SOURCE_DIR}/examples/consumer" -B "${WORK_DIR}/build" -G "${GENERATOR}"
    -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix -DCMAKE_BUILD_TYPE=Release)
run(${CMAKE_COMMAND} --build "${WORK_DIR}/build")
run("${WORK_DIR}/build/consumer")
run("${WORK_DIR}/build/consumer_core_only")
if(PYTHON)
  set(check [=[
import pathlib, sys, ellreloc
assert pathlib.Path(ellreloc.__file__).is_relative_to(sys.argv[1]), ellreloc.__file__
scene = ellreloc.sim.make_scene("office", 1)
camera = ellreloc.Intrinsics(525, 525, 319.5, 239.5, 640, 480)
world = scene.ground_truth_map()
truth = ellreloc.sim.query_trajectory(scene, 1, 0)[0]
result = ellreloc.ObjectRelocalizer(world, camera).relocalize(ellreloc.sim.observe_map(world, camera, truth)[0])
assert ellreloc.pose_error(result.pose, truth).position_cm < 1, result
print("installed Python package:", ellreloc.__file__)
]=])
  run(${CMAKE_COMMAND} -E env "PYTHONPATH=${WORK_DIR}/prefix/${PYTHON_DIR}" ${PYTHON} -c "${check}" "${WORK_DIR}/prefix")
endif()
file(REMOVE_RECURSE "${WORK_DIR}")
