# The STM32G031K8 servo board (Cortex-M0+, 64 MHz, 64 KB flash in 2 KB
# pages, 8 KB RAM); ID, flash map, bus and front end in board.h. Its
# limits are its own (cmake/arm-image.cmake): the slot's 25 pages less the
# update image's 256-byte header, 50 944 B, and the part's 8 KB of RAM.
include(${PROJECT_SOURCE_DIR}/cmake/family-stm32g0.cmake)  # CPU, port, startup
set(SERVO_BOARD_PART stm32g031k8)  # its facts: hal/ports/parts.toml, checked against board.h
# Its code: the G0 boards' shared main.c, boot_main.c and board_io.c (pins,
# clocks, ADC, PWM), which take the bus pin, the bridge and the ADC inputs
# from board.h; a board whose code differs names its own folder here.
set(SERVO_BOARD_CODE ${PROJECT_SOURCE_DIR}/firmware/boards/common/stm32g0)
set(SERVO_BOARD_SOURCES ${SERVO_BOARD_CODE}/board_io.c)
