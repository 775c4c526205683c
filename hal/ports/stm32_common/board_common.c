#include "ports/stm32_common/board_common.h"

#ifdef STM32_FAMILY_G0
#include "ports/stm32g0/stm32g0_regs.h" /* its LSI: IWDG_COUNTS_PER_MS */
#else
#include "ports/stm32_common/stm32_core_regs.h"
#endif

#ifndef IWDG_COUNTS_PER_MS
#define IWDG_COUNTS_PER_MS 10u /* the F0's and F1's 40 kHz LSI / 4 (parts.toml lsi_hz) */
#endif

enum { PWM_HZ = 20000 };

static uint32_t pwm_top;
static uint32_t pwm_timer; /* the board's choice of timer */

volatile uint16_t adc_scan_values[ADC_CHANNELS];

void pwm_bridge_start(uint32_t timer_base, uint32_t timer_hz)
{
    pwm_timer = timer_base;
    pwm_top = timer_hz / PWM_HZ;
    TIM_PSC(timer_base) = 0;
    TIM_ARR(timer_base) = pwm_top - 1u;
    TIM_CCMR1(timer_base) = TIM_CCMR1_PWM1_BOTH;
    TIM_CCR1(timer_base) = 0;
    TIM_CCR2(timer_base) = 0;
    TIM_CCER(timer_base) = TIM_CCER_CC1E_CC2E;
    TIM_EGR(timer_base) = 1u; /* load the preloaded values */
    TIM_CR1(timer_base) = 1u | (1u << 7); /* CEN, ARPE */
}

void pwm_bridge_drive(int16_t duty_q15)
{
    uint32_t magnitude = (uint32_t)(duty_q15 < 0 ? -(int32_t)duty_q15 : duty_q15);
    uint32_t compare = magnitude * pwm_top >> 15;
    TIM_CCR1(pwm_timer) = duty_q15 > 0 ? compare : 0u;
    TIM_CCR2(pwm_timer) = duty_q15 < 0 ? compare : 0u;
}

void pwm_bridge_coast(void)
{
    TIM_CCR1(pwm_timer) = 0;
    TIM_CCR2(pwm_timer) = 0;
}

void iwdg_start(void)
{
    IWDG_KR = IWDG_KEY_START;
    IWDG_KR = IWDG_KEY_ACCESS;
    IWDG_PR = 0; /* LSI / 4 */
    IWDG_RLR = IWDG_TIMEOUT_MS * IWDG_COUNTS_PER_MS;
    IWDG_KR = IWDG_KEY_RELOAD;
}

void iwdg_kick(void)
{
    IWDG_KR = IWDG_KEY_RELOAD;
}

uint32_t unique_id_serial_at(uint32_t uid_addr)
{
    return REG32(uid_addr) ^ REG32(uid_addr + 4u) ^ REG32(uid_addr + 8u);
}

void board_motor_drive(void *ctx, int16_t duty)
{
    (void)ctx;
    pwm_bridge_drive(duty);
}

void board_motor_coast(void *ctx)
{
    (void)ctx;
    pwm_bridge_coast();
}

uint16_t board_encoder_read(void *ctx)
{
    (void)ctx;
    return adc_scan_values[ADC_POSITION];
}

void board_sensors_read(void *ctx, struct sensor_raw *out)
{
    (void)ctx;
    out->supply = adc_scan_values[ADC_SUPPLY];
    out->current = adc_scan_values[ADC_CURRENT];
    out->ntc = adc_scan_values[ADC_NTC];
}
