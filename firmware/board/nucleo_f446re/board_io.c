#include "board_io.h"

void ttt_bio_encoder_init(ttt_bio_encoder *e, uint16_t timer_count)
{
    e->last = timer_count;
    e->count = 0;
}

int32_t ttt_bio_encoder_update(ttt_bio_encoder *e, uint16_t timer_count)
{
    /* the difference modulo 2^16, read as a signed step: the counter may have wrapped either way */
    uint16_t diff = (uint16_t)(timer_count - e->last);
    int32_t step = diff < 0x8000u ? (int32_t)diff : (int32_t)diff - 0x10000;
    e->last = timer_count;
    e->count += step;
    return e->count;
}

void ttt_bio_index_init(ttt_bio_index *ix, int level)
{
    ix->level = level ? 1u : 0u;
    ix->latched = 0;
    ix->edges = 0;
}

void ttt_bio_index_update(ttt_bio_index *ix, int level, int32_t count_at_edge)
{
    uint8_t now = level ? 1u : 0u;
    if (now != ix->level) {
        ix->level = now;
        ix->latched = count_at_edge;
        ix->edges = (uint16_t)(ix->edges + 1u);
    }
}

ttt_bio_bridge ttt_bio_bridge_command(ttt_real duty, ttt_real bridge_on, uint32_t pwm_top)
{
    ttt_bio_bridge b;
    ttt_real magnitude = duty < TTT_R(0.0) ? -duty : duty;
    b.awake = bridge_on > TTT_R(0.5) ? 1u : 0u;
    b.phase = duty > TTT_R(0.0) ? 1u : 0u;
    if (!b.awake || !(magnitude > TTT_R(0.0))) { /* off, zero, or not a number: no drive */
        b.compare = 0;
        b.awake = b.awake && magnitude == magnitude;
        return b;
    }
    if (magnitude > TTT_R(1.0)) magnitude = TTT_R(1.0);
    b.compare = (uint32_t)(magnitude * (ttt_real)pwm_top + TTT_R(0.5));
    if (b.compare > pwm_top) b.compare = pwm_top;
    return b;
}

uint32_t ttt_bio_servo_compare(ttt_real duty, uint32_t period_ticks)
{
    if (!(duty >= TTT_R(0.0))) return 0; /* NaN: no duty computed yet, no pulse */
    if (duty > TTT_R(1.0)) duty = TTT_R(1.0);
    return (uint32_t)(duty * (ttt_real)period_ticks + TTT_R(0.5));
}

uint16_t ttt_bio_servo_feedback(const uint16_t *samples, int n)
{
    uint32_t sum = 0;
    int k;
    if (n < 1) return 0;
    for (k = 0; k < n; k++) sum += samples[k];
    return (uint16_t)((sum + (uint32_t)n / 2u) / (uint32_t)n);
}

float ttt_bio_current_a(uint16_t adc, uint16_t adc_full, float vref, float r_ipropi, float a_ipropi, int phase)
{
    float volts = (float)adc * vref / (float)adc_full;
    float amps = volts / (r_ipropi * a_ipropi);
    return phase ? amps : -amps;
}
