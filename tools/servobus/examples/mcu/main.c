/* A bus master on the reference board (STM32F103, tools/servobus's
 * callback transport; docs/c-library.md): it pings servo 1, reads its
 * angle, moves it between -45 and +45 degrees and reads its state, over
 * and over. USART1 on PA9, one wire (half duplex), 115200 baud: the bus of
 * a new servo. Built as an update image for the board's application slot
 * (behind the board's bootloader, which sets the 72 MHz clock). What it
 * saw is in `master` for a debugger. */
#include <stdint.h>

#include "servobus/servobus.h"

#define REG(addr) (*(volatile uint32_t *)(uintptr_t)(addr))
#define RCC_CR REG(0x40021000u)
#define RCC_CFGR REG(0x40021004u)
#define RCC_APB2ENR REG(0x40021018u)
#define FLASH_ACR REG(0x40022000u)
#define GPIOA_CRH REG(0x40010804u)
#define USART1_SR REG(0x40013800u)
#define USART1_DR REG(0x40013804u)
#define USART1_BRR REG(0x40013808u)
#define USART1_CR1 REG(0x4001380Cu)
#define USART1_CR3 REG(0x40013814u)
#define SYST_CSR REG(0xE000E010u)
#define SYST_RVR REG(0xE000E014u)
#define SYST_CVR REG(0xE000E018u)

#define SYSCLK_HZ 72000000u
#define BAUD 115200u
#define SERVO 1u

struct master_state {
    uint32_t rounds;        /* ping, read, move, monitor: done */
    uint32_t errors;        /* calls that failed */
    sb_status last_status;  /* the last failure's */
    int16_t last_servo;
    uint8_t last_packet;
    int32_t angle;          /* ReadMultiTurnAngle's, 0.1 deg */
    int32_t monitor_angle;  /* the Sync Monitor's */
    uint16_t voltage;       /* mV */
};
volatile struct master_state master;

/* The ms since start in 64 bits, as two words the M3 reads whole (a 32-bit
 * count alone wraps after 49.7 days, and the bus clock with it). */
static volatile uint32_t ms, ms_wraps;

void SysTick_Handler(void);
void SysTick_Handler(void)
{
    if (++ms == 0u)
        ms_wraps++;
}

/* The board's clock, as its bootloader sets it (HSE 8 MHz, PLL x9), if it
 * is not running yet. */
static void clock_init(void)
{
    if ((RCC_CFGR & 0xCu) == 0x8u)
        return;
    RCC_CR |= 1u << 16; /* HSEON */
    while (!(RCC_CR & (1u << 17))) {
    }
    FLASH_ACR = 0x12u; /* two wait states, prefetch */
    RCC_CFGR = (1u << 16) | (7u << 18) | (4u << 8); /* PLL from HSE, x9; APB1 /2 */
    RCC_CR |= 1u << 24;                            /* PLLON */
    while (!(RCC_CR & (1u << 25))) {
    }
    RCC_CFGR |= 2u;
    while ((RCC_CFGR & 0xCu) != 0x8u) {
    }
}

static uint64_t now_us(void *ctx)
{
    uint32_t before, wraps, ticks;
    (void)ctx;
    do { /* again if a tick came in between */
        wraps = ms_wraps;
        before = ms;
        ticks = SYST_RVR - SYST_CVR;
    } while (before != ms || wraps != ms_wraps);
    return ((uint64_t)wraps << 32 | before) * 1000u + ticks / (SYSCLK_HZ / 1000000u);
}

/* A received byte, or -1. Reading DR after SR clears RXNE (and an
 * overrun) on silicon; RXNE is also written 0 (rc_w0), which is how the
 * virtual board's USART model clears it (tools/vboard/usart.py). */
static int uart_recv(void *ctx)
{
    uint32_t byte;
    (void)ctx;
    if (!(USART1_SR & (1u << 5)))
        return -1;
    byte = USART1_DR & 0xFFu;
    USART1_SR = ~(1u << 5);
    return (int)byte;
}

/* The callbacks: bytes out (waiting for the last stop bit, then dropping
 * the echo a one-wire bus hands back), a byte in if one is there. */
static void uart_send(void *ctx, const uint8_t *data, size_t len)
{
    (void)ctx;
    for (size_t k = 0; k < len; k++) {
        while (!(USART1_SR & (1u << 7))) { /* TXE */
        }
        USART1_DR = data[k];
    }
    while (!(USART1_SR & (1u << 6))) { /* TC */
    }
    while (uart_recv(ctx) >= 0) { /* our own bytes */
    }
}

static void bus_init(void)
{
    RCC_APB2ENR |= (1u << 14) | (1u << 2) | 1u;           /* USART1, GPIOA, AFIO */
    GPIOA_CRH = (GPIOA_CRH & ~(0xFu << 4)) | (0xFu << 4); /* PA9: alternate, open drain */
    USART1_BRR = (SYSCLK_HZ + BAUD / 2u) / BAUD;
    USART1_CR3 = 1u << 3;                                 /* HDSEL: one wire */
    USART1_CR1 = (1u << 13) | (1u << 3) | (1u << 2);      /* UE, TE, RE */
    SYST_RVR = SYSCLK_HZ / 1000u - 1u;
    SYST_CVR = 0;
    SYST_CSR = 7u; /* the CPU's clock, interrupt, on */
}

static bool ok(sb_error e)
{
    if (e.status == SB_OK)
        return true;
    master.errors++;
    master.last_status = e.status;
    master.last_servo = e.servo;
    master.last_packet = e.packet;
    return false;
}

static void wait_ms(uint32_t n)
{
    uint64_t until = now_us(NULL) + n * 1000u;
    while (now_us(NULL) < until) {
    }
}

int main(void)
{
    static sb_bus bus;
    static sb_uart uart = {uart_send, uart_recv, now_us, NULL};
    const uint8_t ids[1] = {SERVO};
    int16_t target = 450;
    clock_init();
    bus_init();
    sb_bus_init(&bus, sb_uart_transport(&uart), BAUD);
    for (;;) {
        sb_ping_request ping = {SERVO};
        sb_ping_answer pong;
        sb_read_multi_turn_angle_request read = {SERVO};
        sb_read_multi_turn_angle_answer where;
        sb_move_angle_request move = {SERVO, target, 500, 0};
        sb_monitor_answer state;
        bool got;
        if (!ok(sb_call_ping(&bus, &ping, &pong))) {
            wait_ms(100);
            continue;
        }
        if (ok(sb_call_read_multi_turn_angle(&bus, &read, &where)))
            master.angle = where.angle;
        if (ok(sb_send_move_angle(&bus, &move)))
            target = (int16_t)-target;
        wait_ms(600);
        if (ok(sb_sync_monitor(&bus, ids, 1, &state, &got))) {
            master.monitor_angle = state.angle;
            master.voltage = state.voltage;
        }
        master.rounds++;
    }
}
