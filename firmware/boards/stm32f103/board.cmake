# The reference servo board: STM32F103C8 (Cortex-M3, 72 MHz, 64 KB flash,
# 20 KB RAM), its pins in README.md; ID, flash map and front end in board.h.
set(SERVO_BOARD_CPU cortex-m3)
set(SERVO_BOARD_PORT servo_stm32f1)                      # hal/ports/stm32f1
set(SERVO_BOARD_STARTUP ${PROJECT_SOURCE_DIR}/firmware/startup/startup_stm32f103.c)
set(SERVO_BOARD_SOURCES ${CMAKE_CURRENT_LIST_DIR}/board_io.c)         # pins, clocks, ADC, PWM: this board's
