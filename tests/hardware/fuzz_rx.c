/*
 * The firmware's receive path under AddressSanitizer and UndefinedBehaviorSanitizer
 * (tests/hardware/test_link_sanitized.py).  Reads records from stdin, each a u32
 * length (little-endian), a u8 chunk cut and that many bytes; for each, a fresh
 * firmware takes the bytes in two chunks and runs three control steps, then one
 * line goes to stdout: frames accepted, then the twelve rejection counters.
 * Any memory error or undefined behaviour aborts the process with a report.
 */
#include <stdio.h>
#include <stdlib.h>

#include "ttt_fw/fw.h"

static unsigned char buf[1 << 16];

int main(void)
{
    static ttt_fw fw;
    ttt_board board = {{2e-5, 2e-5, 2.6e-5}, {-3.0f, -3.0f, -3.0f}, {3.0f, 3.0f, 3.0f}, -2.0f, 2.5f, 0.9f,
                       1000u, 50u, 2u, 2u};
    ttt_sensors in = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}, 0, {0.0f, 0.0f, 0.0f}, 2048u};
    unsigned char head[5];
    while (fread(head, 1, 5, stdin) == 5) {
        size_t n = (size_t)head[0] | ((size_t)head[1] << 8) | ((size_t)head[2] << 16) | ((size_t)head[3] << 24);
        size_t cut, i;
        int r;
        if (n > sizeof buf || fread(buf, 1, n, stdin) != n) return 2;
        cut = n ? head[4] % (n + 1) : 0;
        ttt_fw_init(&fw, &board);
        ttt_fw_rx(&fw, buf, cut);
        ttt_fw_rx(&fw, buf + cut, n - cut);
        for (i = 0; i < 3; i++) ttt_fw_control_step(&fw, &in);
        printf("%lu", (unsigned long)ttt_fw_frames_ok(&fw));
        for (r = 0; r < TTT_N_REJ; r++) printf(" %lu", (unsigned long)ttt_fw_rejections(&fw, r));
        printf("\n");
        fflush(stdout);
    }
    return 0;
}
