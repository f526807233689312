/* Checks of the reference board layer's arithmetic (firmware/board/nucleo_f446re/board_io.c):
 * built with the firmware's flags and run by tests/hardware/test_board_io.py.  Prints one line per
 * failed check and exits 1, or "ok" and 0. */
#include <math.h>
#include <stdio.h>

#include "board_io.h"

static int failures = 0;
#define CHECK(cond) do { if (!(cond)) { printf("failed: %s (line %d)\n", #cond, __LINE__); failures++; } } while (0)

int main(void)
{
    ttt_bio_encoder e;
    ttt_bio_index ix;
    ttt_bio_bridge b;
    int32_t k;

    /* counts are relative to power-on, and the 16-bit counter's wrap is followed both ways */
    ttt_bio_encoder_init(&e, 65530u);
    CHECK(ttt_bio_encoder_update(&e, 65530u) == 0);
    CHECK(ttt_bio_encoder_update(&e, 4u) == 10);          /* forward across the wrap */
    CHECK(ttt_bio_encoder_update(&e, 65526u) == -4);      /* back across it */
    for (k = 0; k < 100; k++) (void)ttt_bio_encoder_update(&e, (uint16_t)(65526u + 1000u * (uint32_t)(k + 1)));
    CHECK(e.count == -4 + 100000);                         /* many turns: no count lost */

    /* an index edge, either way, latches the count and is counted */
    ttt_bio_index_init(&ix, 0);
    ttt_bio_index_update(&ix, 0, 5);
    CHECK(ix.edges == 0 && ix.latched == 0);
    ttt_bio_index_update(&ix, 1, 1234);
    CHECK(ix.edges == 1 && ix.latched == 1234 && ix.level == 1);
    ttt_bio_index_update(&ix, 1, 2000);
    CHECK(ix.edges == 1 && ix.latched == 1234);
    ttt_bio_index_update(&ix, 0, -7);
    CHECK(ix.edges == 2 && ix.latched == -7 && ix.level == 0);

    /* the bridge: direction from the sign, compare from the magnitude, asleep when the firmware says off */
    b = ttt_bio_bridge_command(TTT_R(0.25), TTT_R(1.0), 4200u);
    CHECK(b.awake == 1 && b.phase == 1 && b.compare == 1050u);
    b = ttt_bio_bridge_command(TTT_R(-1.5), TTT_R(1.0), 4200u);
    CHECK(b.awake == 1 && b.phase == 0 && b.compare == 4200u);
    b = ttt_bio_bridge_command(TTT_R(0.5), TTT_R(0.0), 4200u);
    CHECK(b.awake == 0 && b.compare == 0u);
    b = ttt_bio_bridge_command((ttt_real)NAN, TTT_R(1.0), 4200u);
    CHECK(b.awake == 0 && b.compare == 0u);

    /* the servo: a NaN duty (not yet computed) sends no pulse; 7.5 % of 20 ms is 1.5 ms */
    CHECK(ttt_bio_servo_compare((ttt_real)NAN, 20000u) == 0u);
    CHECK(ttt_bio_servo_compare(TTT_R(0.075), 20000u) == 1500u);
    CHECK(ttt_bio_servo_compare(TTT_R(2.0), 20000u) == 20000u);

    /* IPROPI: 1 A through 450 uA/A into 2.49 kOhm is 1.1205 V, 1390 counts of 4095 at 3.3 V */
    CHECK(fabsf(ttt_bio_current_a(1390u, 4095u, 3.3f, 2490.0f, 450e-6f, 1) - 1.0f) < 0.002f);
    CHECK(ttt_bio_current_a(1390u, 4095u, 3.3f, 2490.0f, 450e-6f, 0) < -0.99f);

    {   /* the servo's feedback: the mean of its conversions, rounded */
        const uint16_t s[4] = {2000u, 2001u, 2001u, 2001u};
        const uint16_t full[16] = {4095u, 4095u, 4095u, 4095u, 4095u, 4095u, 4095u, 4095u,
                                   4095u, 4095u, 4095u, 4095u, 4095u, 4095u, 4095u, 4095u};
        CHECK(ttt_bio_servo_feedback(s, 4) == 2001u);
        CHECK(ttt_bio_servo_feedback(s, 2) == 2001u);  /* 2000.5 rounds up */
        CHECK(ttt_bio_servo_feedback(s, 1) == 2000u);
        CHECK(ttt_bio_servo_feedback(full, 16) == 4095u);
        CHECK(ttt_bio_servo_feedback(s, 0) == 0u);
    }
    if (failures) return 1;
    printf("ok\n");
    return 0;
}
