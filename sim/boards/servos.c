/*
 * servos.c: the servo outputs of a board as signals: the M128-S's CD4017
 * counters wired to their clock and reset pins ("cnt<c>q<k>", each servo
 * "servo<n>" one counter output), or the servo pins of a board without
 * counters (the M32-D).
 */
#include <stdio.h>

#include "boards/board_model.h"

static void bm_servo_mirror(void *param, signal_t *s, uint64_t cycle, int level)
{
	(void)s;
	signal_set(param, cycle, level);
}

static int bm_counters(board_model_t *bm)
{
	const sim_wiring_t *w = bm->wiring;
	const sim_pin_t *rst = sim_wiring_pin(w, BF_SERVO_RST, 0);
	char name[16];

	for (int c = 0; c < w->servo_counters && c < 4; c++) {
		const sim_pin_t *clk = sim_wiring_pin(w, BF_SERVO_CLK, c);
		bm_port_t *cp = clk ? board_model_port(bm, clk->port) : NULL;

		snprintf(name, sizeof(name), "cnt%d", c);
		if (!cp || cd4017_init(&bm->cnt[c], &bm->signals, name) < 0) {
			return -1;
		}
		signal_listen(&cp->pin[clk->bit], cd4017_on_clock, &bm->cnt[c]);
		if (rst) {
			bm_port_t *reset_port = board_model_port(bm, rst->port);

			if (reset_port) {
				signal_listen(&reset_port->pin[rst->bit], cd4017_on_reset, &bm->cnt[c]);
			}
		}
		bm->ncnt++;
	}
	for (int n = 0; n < bm->ncnt * w->servo_per_counter && n < 32; n++) {
		int c = n / w->servo_per_counter, k = 1 + n % w->servo_per_counter;

		snprintf(name, sizeof(name), "servo%d", n);
		if (signal_add(&bm->signals, &bm->servo[n], name, 0) < 0) {
			return -1;
		}
		signal_listen(&bm->cnt[c].q[k], bm_servo_mirror, &bm->servo[n]);
		bm->nservo++;
	}
	return 0;
}

/* Servo channels on plain pins (the M32-D): "servo<n>" follows channel n's
 * pin, so servos are named alike on every board (`12/servo2`). */
static int bm_servo_pins(board_model_t *bm)
{
	const sim_wiring_t *w = bm->wiring;
	char name[16];

	for (int n = 0; n < 32; n++) {
		const sim_pin_t *p = sim_wiring_pin(w, BF_SERVO, n);
		bm_port_t *port = p ? board_model_port(bm, p->port) : NULL;

		if (!port) {
			break;
		}
		snprintf(name, sizeof(name), "servo%d", n);
		if (signal_add(&bm->signals, &bm->servo[n], name, port->pin[p->bit].level) < 0) {
			return -1;
		}
		signal_listen(&port->pin[p->bit], bm_servo_mirror, &bm->servo[n]);
		bm->nservo++;
	}
	return 0;
}

int board_model_wire_servos(board_model_t *bm)
{
	if (bm_counters(bm) < 0) {
		return -1;
	}
	return bm->wiring->servo_counters ? 0 : bm_servo_pins(bm);
}
