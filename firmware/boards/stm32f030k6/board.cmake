# The Cortex-M0 servo board: STM32F030K6 (48 MHz, 32 KB flash, 4 KB RAM),
# its pins in README.md; ID, flash map and front end in board.h.
# Limits (cmake/check-image.sh), as its board.h gives them: the part's 4 KB RAM; 24 KB flash for the
# application, so the 4 KB bootloader, the application, the 2 KB fault history
# and the 2 KB store fit 32 KB.
include(${PROJECT_SOURCE_DIR}/cmake/family-stm32f0.cmake)  # CPU, port, startup
set(SERVO_BOARD_PART stm32f030k6)  # its facts: hal/ports/parts.toml, checked against board.h
set(SERVO_BOARD_RAM_LIMIT 4096)
set(SERVO_BOARD_FLASH_LIMIT 24320) # the application: its 24 KB slot less the update image's 256-byte header (board.h)
# Its code: the F0 boards' shared main.c, boot_main.c and board_io.c (pins,
# clocks, ADC, PWM), which take the bus pin, the bridge and the ADC inputs
# from board.h; a board whose code differs names its own folder here.
set(SERVO_BOARD_CODE ${PROJECT_SOURCE_DIR}/firmware/boards/common/stm32f0)
set(SERVO_BOARD_SOURCES ${SERVO_BOARD_CODE}/board_io.c)
