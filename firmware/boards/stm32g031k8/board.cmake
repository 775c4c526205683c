# The STM32G031K8 servo board (Cortex-M0+, 64 MHz, 64 KB flash in 2 KB
# pages, 8 KB RAM); ID, flash map, bus and front end in board.h. Its
# limits are its own (cmake/arm-image.cmake): the slot's 25 pages less the
# update image's 256-byte header, 50 944 B, and the part's 8 KB of RAM.
include(${PROJECT_SOURCE_DIR}/cmake/family-stm32g0.cmake)  # CPU, port, startup
set(SERVO_BOARD_PART stm32g031k8)  # its facts: hal/ports/parts.toml, checked against board.h
set(SERVO_BOARD_SOURCES ${CMAKE_CURRENT_LIST_DIR}/board_io.c)         # pins, clocks, ADC, PWM: this board's
