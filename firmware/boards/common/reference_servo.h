/* The reference servo's analogue front end and motor: the reference board
 * (stm32f103/board.h) has them, and the boards that model or copy it
 * include them from here (stm32f030k6, qemu_stm32vl; host_sim through the
 * reference board's board.h). Plain numbers, one per line, as in a board.h
 * (tools/servoctl/board_facts.py follows this include). */
#ifndef BOARDS_COMMON_REFERENCE_SERVO_H
#define BOARDS_COMMON_REFERENCE_SERVO_H

/* The analogue front end: 3.3 V ADC reference; supply through a 100k/10k
 * divider (11:1); 25 mOhm shunt into a gain-of-20 amplifier (0.5 V/A); the
 * NTC divider of docs/protocol.md, "The temperature reading". */
#define BOARD_SUPPLY_UV_PER_COUNT 8862  /* 3.3 V x 11 / 4096 */
#define BOARD_CURRENT_UA_PER_COUNT 1611 /* 3.3 V / 0.5 V/A / 4096 */
#define BOARD_CURRENT_ZERO_COUNTS 0
/* The motor's thermal data (protection/winding.h). Winding plus bridge
 * resistance: the reference servo's (hal/ports/host/plant.c). Winding to
 * case 3.1 K/W, winding time constant 12 s, maximum winding temperature
 * 125 degC: maxon RE 25 (118743) datasheet, "Thermal data" (the motor the
 * simulator's thermal model takes, hal/ports/host/thermal.h). */
#define BOARD_MOTOR_MOHM 2741
#define BOARD_WINDING_CASE_MK_PER_W 3100
#define BOARD_WINDING_TAU_MS 12000
#define BOARD_WINDING_LIMIT_DECIC 1250

#endif
