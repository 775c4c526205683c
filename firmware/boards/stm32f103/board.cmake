# The reference servo board: STM32F103C8 (Cortex-M3, 72 MHz, 64 KB flash,
# 20 KB RAM), its pins in README.md, its sensor front end in calibration.h.
set(SERVO_BOARD_CPU cortex-m3)
set(SERVO_BOARD_PORT servo_stm32f1)                      # hal/ports/stm32f1
set(SERVO_BOARD_STARTUP ${PROJECT_SOURCE_DIR}/firmware/startup/startup_stm32f103.c)
set(SERVO_BOARD_LINKER ${CMAKE_CURRENT_LIST_DIR}/stm32f103x8.ld)
set(SERVO_BOARD_ID 0x0103)                                 # the update image header's board
set(SERVO_BOARD_BOOT_LINKER ${CMAKE_CURRENT_LIST_DIR}/stm32f103x8_boot.ld)
