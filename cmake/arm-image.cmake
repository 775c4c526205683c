# servo_arm_image(NAME SOURCES src... [LIBS lib...]): the image of the board
# whose board.cmake was included last (its startup code, port library and
# linker script), a .bin beside it, a map, and the budget / soft-float and
# stack checks after every link.
function(servo_arm_image name)
  cmake_parse_arguments(I "" "" "SOURCES;LIBS" ${ARGN})
  if(NOT SERVO_BOARD_CPU STREQUAL SERVO_CPU)
    message(FATAL_ERROR "${name}: the board is a ${SERVO_BOARD_CPU}; this build is for ${SERVO_CPU}")
  endif()
  set(I_LINKER ${SERVO_BOARD_LINKER})
  add_executable(${name}.elf ${I_SOURCES} ${SERVO_BOARD_STARTUP})
  target_link_libraries(${name}.elf PRIVATE ${I_LIBS} ${SERVO_BOARD_PORT} servo_app)
  target_include_directories(${name}.elf PRIVATE ${PROJECT_SOURCE_DIR}/firmware/boards/stm32f103)
  servo_firmware_target(${name}.elf)
  target_link_options(${name}.elf PRIVATE -L${PROJECT_SOURCE_DIR}/firmware/linker -T${I_LINKER}
                      -Wl,-Map=${CMAKE_CURRENT_BINARY_DIR}/${name}.map)
  set_target_properties(${name}.elf PROPERTIES
    LINK_DEPENDS "${I_LINKER};${PROJECT_SOURCE_DIR}/firmware/linker/sections_stm32f1.ld")
  add_custom_command(TARGET ${name}.elf POST_BUILD
    COMMAND ${CMAKE_OBJCOPY} -O binary $<TARGET_FILE:${name}.elf> ${CMAKE_CURRENT_BINARY_DIR}/${name}.bin
    COMMAND sh ${PROJECT_SOURCE_DIR}/cmake/check-image.sh $<TARGET_FILE:${name}.elf>
    COMMAND Python3::Interpreter ${PROJECT_SOURCE_DIR}/cmake/stack-report.py
            $<TARGET_FILE:${name}.elf> ${CMAKE_BINARY_DIR}
    VERBATIM)
endfunction()
