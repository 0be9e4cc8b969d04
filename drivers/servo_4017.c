/*
 * Servo pulses through CD4017 decade counters (M128-S: 32 channels).
 *
 * Counter c is clocked by a timer compare output (OC3A, OC3B, OC3C, OC1C);
 * all four share a reset line. After the reset at a frame's start a counter
 * sits in Q0 (not wired); each rising clock edge moves it on, so output
 * Q(k+1), channel 8c+k, is high from one rising edge to the next, and Q9
 * (not wired either) is where it rests until the next frame.
 *
 * Every rising edge that starts or ends a pulse is made by the timer
 * hardware (set on compare match, clk/8 = 1.085 us ticks): widths are exact
 * to the tick whatever the rest of the firmware does. The compare interrupt
 * that follows brings the clock line low again with a forced compare (FOC,
 * clear mode) and programs the next rise.
 *
 * A counter cannot skip an output. Off channels between pulsing ones are
 * passed by the same interrupt with forced compares, a clock pulse of about
 * 1.5 us each, so an off channel's output sees a pulse of a few
 * microseconds: the first of a run of off channels from the hardware rise
 * until the interrupt runs, the last until the next hardware rise
 * SERVO_PASS ticks after the run began; servos ignore pulses that short.
 * After a counter's last pulsing channel the interrupt runs it through to
 * Q9. A counter with no channel on is not clocked at all. A frame is 20 ms
 * unless one counter's widths add up to more than fits (8 x 2.5 ms does
 * not): then the frame stretches to fit.
 *
 * One interrupt per hardware rise, at most nine per counter and frame, at
 * least SERVO_PASS ticks apart: four counters never keep the CPU busy.
 */
#include "drivers/servo_hw.h"

#include <avr/interrupt.h>
#include <avr/io.h>
#include <util/atomic.h>

#include "board.h"
#include "drivers/drv_servo.h"
#include "firmware/board_pins.h"
#include "firmware/front.h"
#include "firmware/mcu.h"
#include "firmware/pins.h"

#define SERVO_TICK_HZ (F_CPU / 8)           /* 921.6 kHz */
#define SERVO_FRAME   18432u                /* 20 ms in ticks */
#define SERVO_LEAD    256u                  /* frame start to counter 0's first rise */
#define SERVO_STAGGER 96u                   /* counter c starts c x this later */
#define SERVO_PASS    24u                   /* run of off channels: first to next rise, */
#define SERVO_PASS_STEP 4u                  /* plus this per forced clock */
#define SERVO_AHEAD   4u                    /* a rise is programmed at least this far ahead */
#define SERVO_TAIL    64u                   /* last rise to the next frame, at least */
#define SERVO_COUNTERS BOARD_SERVO_COUNTERS
#define SERVO_SLOTS   BOARD_SERVO_PER_COUNTER
/* Hardware rises per counter and frame: each enters a different output
 * Q1..Q(SLOTS + 1). */
#define SERVO_RISES   (SERVO_SLOTS + 1u)
#define SERVO_REST    0x80u                 /* steps[]: then rest in Q9, clock off */
/* Forced clock phases: >= 1 us high and low (CD4017B at 5 V: 200 ns). */
#define SERVO_FOC_WAIT 4u

_Static_assert(SERVO_COUNTERS * SERVO_SLOTS == SERVO_CHANNELS, "channels = counters x slots");
_Static_assert(SERVO_COUNTERS == 4, "one compare unit per counter: OC3A, OC3B, OC3C, OC1C");

/* What the interrupt after one hardware rise does: pass `steps` off
 * outputs with forced clocks (SERVO_REST: through to Q9 and stop), then
 * program the next rise `dur` ticks after this one. */
typedef struct {
	uint16_t dur;
	uint8_t steps;
} servo_step_t;

/* One frame's plan, made by servo_hw_apply() outside any interrupt so the
 * compare interrupts only read it: entry i of counter c is for its i-th
 * hardware rise. */
typedef struct {
	servo_step_t step[SERVO_COUNTERS][SERVO_RISES];
	uint16_t first[SERVO_COUNTERS];             /* first rise after the frame start */
	uint16_t frame;                             /* frame length, ticks */
	uint8_t units;                              /* ETIMSK bits of the running counters */
	uint8_t com3, com1;                         /* their COM bits (set on match) */
} frame_plan_t;

static struct {
	frame_plan_t sched[2];
	volatile uint8_t cur;
	volatile uint8_t pending;
	volatile uint8_t running;
	const servo_step_t *next[SERVO_COUNTERS];  /* counter c's next entry in sched[cur] */
	uint16_t t3_offset;                     /* TCNT3 - TCNT1 */
	volatile uint8_t *rst_port;             /* the reset line's PORT register */
	uint8_t rst_mask;
} pulses;

/* The compare interrupts outrank the serial line's receive interrupt and
 * can come back to back (four counters, and the frame start): above 115200
 * baud that is longer than the USART holds received characters (two: 320
 * cycles at 460800). Each ends letting a waiting character's interrupt in:
 * every width is the hardware's, and the next rise is programmed already:
 * front_rx_poll(FRONT_HOLD_ALL) at the end of each below. */

/*
 * Counter c's compare unit made a rising edge: the counter moved on. Bring
 * the clock low, pass the off outputs that follow, program the next rise
 * from this one (so a late interrupt never changes a width) or rest.
 * Inlined into each compare vector with its unit's registers as constants.
 *
 * A compare unit's COM bits: 0 off (the pin follows PORT: low), 2 clear,
 * 3 set on match; flipping the low bit (`flip`) turns set into clear and
 * back.
 */
static inline __attribute__((always_inline)) void
servo_rise(uint8_t c, volatile uint16_t *ocr, volatile uint16_t *tcnt, volatile uint8_t *tccr,
	   uint8_t com0, volatile uint8_t *focr, uint8_t foc)
{
	const uint8_t flip = (uint8_t)(1u << com0);

	*tccr ^= flip;          /* set -> clear */
	*focr = foc;            /* clock low */
	const servo_step_t *e = pulses.next[c];
	pulses.next[c] = e + 1;
	uint8_t steps = e->steps;
	uint16_t dur = e->dur;
	for (uint8_t k = steps & (uint8_t)~SERVO_REST; k; k--) {
		__builtin_avr_delay_cycles(SERVO_FOC_WAIT);
		*tccr ^= flip;
		*focr = foc;    /* high: the next output */
		__builtin_avr_delay_cycles(SERVO_FOC_WAIT);
		*tccr ^= flip;
		*focr = foc;    /* low */
	}
	if (steps & SERVO_REST) {
		*tccr &= (uint8_t)~(3u << com0);
		front_rx_poll(FRONT_HOLD_ALL);
		return;
	}
	*tccr ^= flip;          /* clear -> set: the next rise */
	uint16_t at = *ocr + dur;
	uint16_t now = *tcnt;
	if ((int16_t)(at - now) < (int16_t)SERVO_AHEAD) {
		at = now + SERVO_AHEAD;
	}
	*ocr = at;
	front_rx_poll(FRONT_HOLD_ALL);
}

ISR(TIMER3_COMPA_vect) { servo_rise(0, &OCR3A, &TCNT3, &TCCR3A, COM3A0, &TCCR3C, _BV(FOC3A)); }
ISR(TIMER3_COMPB_vect) { servo_rise(1, &OCR3B, &TCNT3, &TCCR3A, COM3B0, &TCCR3C, _BV(FOC3B)); }
ISR(TIMER3_COMPC_vect) { servo_rise(2, &OCR3C, &TCNT3, &TCCR3A, COM3C0, &TCCR3C, _BV(FOC3C)); }
ISR(TIMER1_COMPC_vect) { servo_rise(3, &OCR1C, &TCNT1, &TCCR1A, COM1C0, &TCCR1C, _BV(FOC1C)); }

#define UNITS_ALL (_BV(OCIE3A) | _BV(OCIE3B) | _BV(OCIE3C) | _BV(OCIE1C))
#define COM3_ALL (_BV(COM3A1) | _BV(COM3A0) | _BV(COM3B1) | _BV(COM3B0) | _BV(COM3C1) | _BV(COM3C0))
#define COM1C_ALL (_BV(COM1C1) | _BV(COM1C0))

/* Frame start (Timer1 compare A): reset the counters, start the active
 * ones. Everything it writes was worked out by servo_hw_apply().
 *
 * It lets a waiting character's interrupt in first, too: its work (about
 * 230 cycles to the poll at its end) is more than the USART's room left
 * when it starts after a character has waited a while already (a UDRE
 * interrupt ran, the outranked receive interrupt waits: 54 + 230 + the
 * poll > 320 cycles at 460800, a character lost while a reply goes out).
 * Nothing here is due before counter 0's first rise, SERVO_LEAD ticks
 * after OCR1A's match, on which the plan's times are based. */
ISR(TIMER1_COMPA_vect)
{
	front_rx_poll(FRONT_HOLD_ALL);
	uint16_t f = OCR1A;
	if (pulses.pending) {
		pulses.cur ^= 1;
		pulses.pending = 0;
	}
	const frame_plan_t *s = &pulses.sched[pulses.cur];
	/* Counters 0-2 count on Timer3, counter 3 on Timer1. An idle unit's
	 * OCR is written too: with its COM bits off it does nothing. */
	uint16_t f3 = f + pulses.t3_offset;
	OCR3A = f3 + s->first[0];
	OCR3B = f3 + s->first[1];
	OCR3C = f3 + s->first[2];
	OCR1C = f + s->first[3];
	for (uint8_t c = 0; c < SERVO_COUNTERS; c++) {
		pulses.next[c] = s->step[c];
	}
	TCCR3A = (uint8_t)((TCCR3A & (uint8_t)~COM3_ALL) | s->com3);
	TCCR1A = (uint8_t)((TCCR1A & (uint8_t)~COM1C_ALL) | s->com1);
	/* A match from before (the unit idled, or the last frame) must not
	 * count as this frame's first rise. */
	ETIFR = s->units;
	ETIMSK = (uint8_t)((ETIMSK & (uint8_t)~UNITS_ALL) | s->units);
	/* Reset pulse, well before the first clock: CD4017 needs 0.3 us at
	 * 5 V; this is about 2.5 us. */
	*pulses.rst_port |= pulses.rst_mask;
	__builtin_avr_delay_cycles(16);
	if (!s->units) {
		/* Nothing pulses: counters held in reset, interrupts off. */
		pulses.running = 0;
		TIMSK &= (uint8_t)~_BV(OCIE1A);
		return;
	}
	*pulses.rst_port &= (uint8_t)~pulses.rst_mask;
	OCR1A = f + s->frame;
	front_rx_poll(FRONT_HOLD_ALL);
}

void servo_hw_init(void)
{
	pulses.running = 0;
	pulses.pending = 0;
	pulses.cur = 0;
	pulses.sched[0].units = 0;
	/* Clock lines low, reset held high: all outputs quiet. */
	for (uint8_t c = 0; c < SERVO_COUNTERS; c++) {
		uint8_t pin = board_pin(BF_SERVO_CLK, c);
		pins_claim(pin, PIN_SERVO_CLK);
		pins_drive(pin, false);
	}
	uint8_t rst = board_pin_at(BF_SERVO_RST, 0);
	pins_claim(rst, PIN_SERVO_CLK);
	pulses.rst_port = mcu_port(PIN_PORT(rst)).port;
	pulses.rst_mask = PIN_MASK(rst);
	pins_drive(rst, true);
	/* Timer1 and Timer3: normal mode, clk/8, started together. */
	SFIOR = _BV(TSM) | _BV(PSR321);
	TCCR1A = 0;
	TCCR3A = 0;
	TCNT1 = 0;
	TCNT3 = 0;
	TCCR1B = _BV(CS11);
	TCCR3B = _BV(CS31);
	SFIOR = 0;
	/* However the two started, they count alike from here: one offset
	 * maps Timer1 (the frame) to Timer3 (counters 0-2). */
	ATOMIC_BLOCK(ATOMIC_RESTORESTATE) {
		uint16_t t1 = TCNT1;
		uint16_t t3 = TCNT3;
		pulses.t3_offset = t3 - t1;
	}
}

bool servo_hw_can_claim(uint8_t ch)
{
	(void)ch;
	return true;
}

bool servo_hw_claim(uint8_t ch)
{
	(void)ch;  /* channels have no MCU pins: the counters' lines are ours */
	return true;
}

void servo_hw_release(uint8_t ch)
{
	(void)ch;
}

/* Timer ticks for a width in microseconds, rounded to the nearest: us x
 * 0.9216 as a 16.16 product. A 16 x 16-bit multiply, not a 32-bit division
 * (about 600 cycles a channel, 32 channels a plan); for every width up to
 * 2500 us it gives what (us x 9216 + 5000) / 10000 gives. */
#define SERVO_TICKS_PER_US_Q16 ((uint16_t)((SERVO_TICK_HZ * 65536ULL + 500000ULL) / 1000000ULL))
static uint16_t servo_ticks_of(uint16_t us)
{
	return (uint16_t)(((uint32_t)us * SERVO_TICKS_PER_US_Q16 + 32768UL) >> 16);
}

/* Plans counter c: its hardware rises, the off outputs passed after each
 * and the ticks between rises. Returns the last rise's time, or 0 when no
 * channel of the counter is on. */
static uint16_t counter_plan(frame_plan_t *s, uint8_t c, const uint16_t *widths_us)
{
	servo_step_t *e = s->step[c];
	uint16_t t = SERVO_LEAD + c * SERVO_STAGGER;
	uint8_t k = 0;  /* the output a rise enters: slot k, Q(k+1) */

	s->first[c] = t;
	for (;;) {
		if (k == SERVO_SLOTS) {
			e->steps = SERVO_REST;  /* the last pulse ended in Q9 */
			return t;
		}
		uint16_t us = widths_us[k];
		if (us) {
			e->steps = 0;
			e->dur = servo_ticks_of(us);
			t = (uint16_t)(t + e->dur);
			e++;
			k++;
			continue;
		}
		uint8_t m = k;  /* the run of off outputs k..m-1 */
		while (m < SERVO_SLOTS && !widths_us[m]) {
			m++;
		}
		if (m == SERVO_SLOTS) {
			if (k == 0) {
				return 0;  /* no channel on */
			}
			e->steps = (uint8_t)(SERVO_REST | (SERVO_SLOTS - k));  /* through to Q9 */
			return t;
		}
		e->steps = (uint8_t)(m - k - 1u);
		e->dur = (uint16_t)(SERVO_PASS + SERVO_PASS_STEP * e->steps);
		t = (uint16_t)(t + e->dur);
		e++;
		k = m;
	}
}

/* Nothing waits: each counter's frame is planned at once. */
void servo_hw_later(const uint16_t *widths_us)
{
	(void)widths_us;
}

void servo_hw_apply(const uint16_t *widths_us)
{
	pulses.pending = 0;  /* the frame interrupt must not take it half written */
	frame_plan_t *s = &pulses.sched[pulses.cur ^ 1];
	static const __flash uint8_t unit[SERVO_COUNTERS] = {
		_BV(OCIE3A), _BV(OCIE3B), _BV(OCIE3C), _BV(OCIE1C),
	};
	static const __flash uint8_t com_set[SERVO_COUNTERS] = {
		_BV(COM3A1) | _BV(COM3A0), _BV(COM3B1) | _BV(COM3B0), _BV(COM3C1) | _BV(COM3C0),
		_BV(COM1C1) | _BV(COM1C0),
	};
	uint16_t frame = SERVO_FRAME;
	s->units = 0;
	s->com3 = 0;
	s->com1 = 0;
	for (uint8_t c = 0; c < SERVO_COUNTERS; c++) {
		uint16_t last = counter_plan(s, c, widths_us + c * SERVO_SLOTS);
		if (last) {
			s->units |= unit[c];
			if (c < 3) {
				s->com3 |= com_set[c];
			} else {
				s->com1 |= com_set[c];
			}
			if ((uint16_t)(last + SERVO_TAIL) > frame) {
				frame = (uint16_t)(last + SERVO_TAIL);
			}
		}
	}
	s->frame = frame;
	ATOMIC_BLOCK(ATOMIC_RESTORESTATE) {
		if (pulses.running) {
			pulses.pending = 1;
		} else if (s->units) {
			pulses.cur ^= 1;
			pulses.running = 1;
			OCR1A = TCNT1 + 256;
			TIMSK |= _BV(OCIE1A);
		}
	}
}
