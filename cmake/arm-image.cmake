# servo_arm_image(NAME LINKER script SOURCES src...): an STM32F1 image with
# the startup code, a .bin beside it, a map, and the budget / soft-float
# check after every link.
function(servo_arm_image name)
  cmake_parse_arguments(I "" "LINKER" "SOURCES;LIBS" ${ARGN})
  add_executable(${name}.elf ${I_SOURCES} ${PROJECT_SOURCE_DIR}/firmware/startup/startup_stm32f103.c)
  target_link_libraries(${name}.elf PRIVATE ${I_LIBS} servo_stm32f1 servo_app)
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
