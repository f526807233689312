/*
 * ttt_sm firmware, board layer for the reference build: an ST Nucleo-F446RE
 * (STM32F446RE, Cortex-M4F at 180 MHz) with the STM32 Arduino core
 * (STM32duino), three Pololu DRV8874 H-bridge carriers, three 500-line
 * quadrature encoders on the motor shafts, three slotted optical index
 * switches and the pen's hobby servo.  Wiring: docs/hardware.md, "The
 * reference build".
 *
 * NOT FLASHED, NOT COMPILED FOR THE BOARD: this sketch was written against
 * the STM32duino API and has not been built with it nor run on a Nucleo.
 * What it computes is in board_io.c (compiled and checked on the PC by
 * tests/hardware/test_board_io.py); the firmware's core (../../src,
 * ../../include) is the C the tests run in the emulator.
 *
 * To build: copy (or link) firmware/src/*.c, firmware/include/ttt_fw/,
 * board_io.{c,h} and arm_board.h into this sketch's src/ folder, so the Arduino IDE compiles
 * them with the sketch; select the board "Nucleo-64 / Nucleo F446RE",
 * "Optimize: Smallest (-Os) with LTO" off, C runtime "Newlib Nano".
 */
#include <Arduino.h>
#include <HardwareTimer.h>
#include <Servo.h>

extern "C" {
#include "src/arm_board.h" /* the arm's numbers, generated from arm.toml */
#include "src/board_io.h"
#include "src/ttt_fw/fw.h"
}

/* ---- pins (Arduino names of the Nucleo-64 headers; STM32 pins in the comments) ------------------------- */
static const uint32_t PIN_EN[3] = {PA8, PA9, PA10};   /* TIM1 CH1..CH3: DRV8874 EN (PWM, 20 kHz) */
static const uint32_t PIN_PH[3] = {PB3, PB5, PB4};    /* DRV8874 PH (direction) */
static const uint32_t PIN_SLEEP[3] = {PB10, PC9, PC6};/* DRV8874 nSLEEP: low, the bridge's outputs are off */
static const uint32_t PIN_FAULT = PC8;                /* DRV8874 nFAULT, open drain, the three wired together */
static const uint32_t PIN_IPROPI[3] = {PA4, PB0, PC1};/* DRV8874 IPROPI across 2.49 kOhm: ADC1 */
static const uint32_t PIN_INDEX[3] = {PC10, PC11, PC12};  /* index switches (open collector, pull-up) */
static const uint32_t PIN_SERVO = PC7;                /* the pen's servo, 50 Hz */
static const uint32_t PIN_SERVO_FB = PC0;             /* A5: its feedback wire (the pot's wiper) through
                                                         10 kOhm / 100 nF to ground: ADC1 IN10 */
static const int SERVO_FB_SAMPLES = 16;               /* conversions averaged per control step */
/* encoders: TIM2 (PA0, PA1), TIM3 (PA6, PA7), TIM4 (PB6, PB7) in encoder mode, x4 decoding */

static const uint32_t PWM_HZ = 20000;

static ttt_fw fw;
static ttt_sensors sensors;
static ttt_bio_encoder enc[3];
static ttt_bio_index idx[3];
static TIM_HandleTypeDef enc_tim[3];
static HardwareTimer *pwm = nullptr;
static HardwareTimer *tick = nullptr;
static Servo servo;
static volatile uint8_t control_due = 0;

static void encoder_timer(TIM_HandleTypeDef *h, TIM_TypeDef *instance)
{
    TIM_Encoder_InitTypeDef cfg = {};
    h->Instance = instance;
    h->Init.Prescaler = 0;
    h->Init.CounterMode = TIM_COUNTERMODE_UP;
    h->Init.Period = 0xFFFF;  /* 16 bits on every timer: board_io unwraps */
    h->Init.ClockDivision = TIM_CLOCKDIVISION_DIV1;
    cfg.EncoderMode = TIM_ENCODERMODE_TI12;
    cfg.IC1Polarity = TIM_ICPOLARITY_RISING;
    cfg.IC1Selection = TIM_ICSELECTION_DIRECTTI;
    cfg.IC1Filter = 4;
    cfg.IC2Polarity = TIM_ICPOLARITY_RISING;
    cfg.IC2Selection = TIM_ICSELECTION_DIRECTTI;
    cfg.IC2Filter = 4;
    HAL_TIM_Encoder_Init(h, &cfg);
    HAL_TIM_Encoder_Start(h, TIM_CHANNEL_ALL);
}

static void on_tick(void) { control_due = 1; }

void setup()
{
    ttt_board board;
    ttt_arm_board(&board); /* the control period, a STATUS every chart step, the watchdog: arm_board.h */
    ttt_fw_init(&fw, &board);

    Serial.begin(921600);  /* the ST-LINK's virtual COM port (USART2, PA2/PA3) */

    pinMode(PIN_FAULT, INPUT_PULLUP);
    analogReadResolution(12);
    for (int d = 0; d < 3; d++) {
        pinMode(PIN_SLEEP[d], OUTPUT);
        digitalWrite(PIN_SLEEP[d], LOW);  /* bridges off until the firmware powers a drive */
        pinMode(PIN_PH[d], OUTPUT);
        pinMode(PIN_INDEX[d], INPUT_PULLUP);
    }
    pwm = new HardwareTimer(TIM1);
    for (int d = 0; d < 3; d++) pwm->setMode(d + 1, TIMER_OUTPUT_COMPARE_PWM1, PIN_EN[d]);
    pwm->setOverflow(PWM_HZ, HERTZ_FORMAT);
    for (int d = 0; d < 3; d++) pwm->setCaptureCompare(d + 1, 0, TICK_COMPARE_FORMAT);
    pwm->resume();

    encoder_timer(&enc_tim[0], TIM2);
    encoder_timer(&enc_tim[1], TIM3);
    encoder_timer(&enc_tim[2], TIM4);
    for (int d = 0; d < 3; d++) {
        ttt_bio_encoder_init(&enc[d], (uint16_t)__HAL_TIM_GET_COUNTER(&enc_tim[d]));
        ttt_bio_index_init(&idx[d], digitalRead(PIN_INDEX[d]));
    }
    servo.attach(PIN_SERVO);  /* no pulse is written until the firmware computes a duty */

    tick = new HardwareTimer(TIM6);
    tick->setOverflow(board.control_period_us, MICROSEC_FORMAT);  /* 1000 us: 1 kHz */
    tick->attachInterrupt(on_tick);
    tick->resume();
}

static void control_step(void)
{
    uint8_t levels = 0;
    for (int d = 0; d < 3; d++) {
        int32_t c = ttt_bio_encoder_update(&enc[d], (uint16_t)__HAL_TIM_GET_COUNTER(&enc_tim[d]));
        /* the index is sampled at the control rate: the latched count is within one step's travel */
        ttt_bio_index_update(&idx[d], digitalRead(PIN_INDEX[d]), c);
        sensors.counts[d] = c;
        sensors.index_count[d] = idx[d].latched;
        sensors.index_edges[d] = idx[d].edges;
        if (idx[d].level) levels |= (uint8_t)(1u << d);
        sensors.current_a[d] = ttt_bio_current_a((uint16_t)analogRead(PIN_IPROPI[d]), 4095u, 3.3f, 2490.0f,
                                                 450e-6f, digitalRead(PIN_PH[d]));
    }
    sensors.index = levels;
    uint16_t fb[SERVO_FB_SAMPLES];
    for (int k = 0; k < SERVO_FB_SAMPLES; k++) fb[k] = (uint16_t)analogRead(PIN_SERVO_FB);
    sensors.servo_adc = ttt_bio_servo_feedback(fb, SERVO_FB_SAMPLES);
    ttt_fw_control_step(&fw, &sensors);

    const ttt_real *act = fw.cascade.act;
    int fault = digitalRead(PIN_FAULT) == LOW;  /* a bridge reports overcurrent or overheating: all off */
    for (int d = 0; d < 3; d++) {
        ttt_bio_bridge b = ttt_bio_bridge_command(act[TTT_ACT_DUTY + d], act[TTT_ACT_BRIDGE + d],
                                                  pwm->getOverflow(TICK_FORMAT));
        digitalWrite(PIN_PH[d], b.phase ? HIGH : LOW);
        pwm->setCaptureCompare(d + 1, b.compare, TICK_COMPARE_FORMAT);
        digitalWrite(PIN_SLEEP[d], b.awake && !fault ? HIGH : LOW);
    }
    uint32_t pulse_us = ttt_bio_servo_compare(act[TTT_ACT_SV_DUTY], 20000u);  /* 20 ms period, in us */
    if (pulse_us) servo.writeMicroseconds((int)pulse_us);
}

void loop()
{
    uint8_t buf[64];
    size_t n = 0;
    while (Serial.available() && n < sizeof buf) buf[n++] = (uint8_t)Serial.read();
    if (n) ttt_fw_rx(&fw, buf, n);
    if (control_due) {
        control_due = 0;
        control_step();
    }
    uint8_t out[64];
    size_t m = ttt_fw_tx(&fw, out, (size_t)Serial.availableForWrite() < sizeof out
                                       ? (size_t)Serial.availableForWrite() : sizeof out);
    if (m) Serial.write(out, m);
}
