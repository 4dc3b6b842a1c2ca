# Run at every build (cmake -P, from CMakeLists.txt): the product must not depend on the
# simulator or the judges. Fails the build when a runtime header or source includes a
# sim/ or eval/ header. SOURCE_DIR is the package's source folder.
set(runtime geometry tracking planes mapping viz params ros nodelets)
set(bad_files "")
foreach(stage ${runtime})
  file(GLOB files ${SOURCE_DIR}/include/mono_plane_detection/${stage}/*.h
       ${SOURCE_DIR}/src/${stage}/*.h ${SOURCE_DIR}/src/${stage}/*.cpp)
  foreach(f ${files})
    file(STRINGS ${f} lines REGEX "#include \"mono_plane_detection/(sim|eval)/")
    if(lines)
      list(APPEND bad_files "${f}: ${lines}")
    endif()
  endforeach()
endforeach()
if(bad_files)
  string(REPLACE ";" "\n  " listing "${bad_files}")
  message(FATAL_ERROR "runtime code includes the simulator or an evaluator "
                      "(docs/architecture.md):\n  ${listing}")
endif()
