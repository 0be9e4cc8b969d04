/*
 * Servo pulses through CD4017 decade counters (M128-S: 32 channels).
 *
 * Counter c is clocked by a timer compare output (OC3A, OC3B, OC3C, OC1C),
 * all four share a reset line. After the reset at a frame's start a counter
 * sits in Q0 (idle); each clock's rising edge moves it on, so output Q(k+1),
 * channel 8c+k, is high from one rising edge to the next. Every edge is made
 * by the timer hardware (set / clear on compare match, clk/8 = 1.085 us
 * ticks), the compare interrupt only programs the next one: widths are
 * exact to the tick whatever the rest of the firmware does.
 *
 * A counter cannot skip an output: a channel that is off but lies on a
 * counter with pulsing channels is passed in SERVO_GAP ticks (a short pulse
 * servos ignore); a counter with no channel on is not clocked at all and all
 * its outputs stay low. A frame is 20 ms unless one counter's widths add up
 * to more than fits (8 x 2.5 ms does not): then the frame stretches to fit.
 */
#include "drivers/servo_hw.h"

#include <avr/interrupt.h>
#include <avr/io.h>
#include <util/atomic.h>

#include "board.h"
#include "drivers/drv_servo.h"
#include "firmware/board_pins.h"
#include "firmware/mcu.h"
#include "firmware/pins.h"
#include "firmware/port_io.h"

#define SERVO_TICK_HZ (F_CPU / 8)           /* 921.6 kHz */
#define SERVO_FRAME   18432u                /* 20 ms in ticks */
#define SERVO_HIGH    40u                   /* clock pulse high time */
#define SERVO_GAP     80u                   /* slot of a channel that is off */
#define SERVO_LEAD    256u                  /* frame start to first clock */
#define SERVO_COUNTERS BOARD_SERVO_COUNTERS
#define SERVO_SLOTS   BOARD_SERVO_PER_COUNTER

_Static_assert(SERVO_COUNTERS * SERVO_SLOTS == SERVO_CHANNELS, "channels = counters x slots");

typedef struct {
	uint16_t dur[SERVO_COUNTERS][SERVO_SLOTS];  /* slot lengths, ticks */
	uint16_t frame;                             /* frame length, ticks */
	uint8_t active;                             /* bit c: counter c runs */
} servo_sched_t;

static struct {
	servo_sched_t sched[2];
	volatile uint8_t cur;
	volatile uint8_t pending;
	volatile uint8_t running;
	uint8_t rises[SERVO_COUNTERS];     /* rising edges done this frame */
	uint8_t high[SERVO_COUNTERS];      /* the clock line is high */
	uint16_t rise_at[SERVO_COUNTERS];  /* tick of the last rising edge */
	uint16_t t3_offset;                /* TCNT3 - TCNT1 */
	volatile uint8_t *rst_port;        /* the reset line's PORT register */
	uint8_t rst_mask;
} s4;

/* Compare unit of counter c: its OCR, its COM bits' register and shift. */
static volatile uint16_t *servo_ocr(uint8_t c)
{
	switch (c) {
	case 0: return &OCR3A;
	case 1: return &OCR3B;
	case 2: return &OCR3C;
	default: return &OCR1C;
	}
}

static const __flash uint8_t com_shift[SERVO_COUNTERS] = { COM3A0, COM3B0, COM3C0, COM1C0 };

/* COM bits: 0 off (the pin follows PORT: low), 2 clear, 3 set on match. */
static void servo_com(uint8_t c, uint8_t com)
{
	volatile uint8_t *tccr = (c < 3) ? &TCCR3A : &TCCR1A;
	uint8_t shift = com_shift[c];
	*tccr = (uint8_t)((*tccr & ~(3u << shift)) | (uint8_t)(com << shift));
}

#define COM_OFF 0
#define COM_CLEAR 2
#define COM_SET 3

/* Programs counter c's next edge at tick `at`. A late interrupt must not
 * lose an edge (the counter would drift a slot): an edge whose time has
 * passed comes right away. Only a clock fall or the end of an off channel's
 * short slot can be that close; a pulsing channel's end is >= 461 ticks
 * after its start. */
static void servo_next(uint8_t c, volatile uint16_t *ocr, uint16_t at)
{
	uint16_t now = (c < 3) ? TCNT3 : TCNT1;
	if ((int16_t)(at - now) < 4) {
		at = now + 4;
	}
	*ocr = at;
}

/* A counter's compare matched: program its next edge. */
static void servo_counter_edge(uint8_t c)
{
	volatile uint16_t *ocr = servo_ocr(c);
	uint16_t t = *ocr;
	const servo_sched_t *s = &s4.sched[s4.cur];
	uint16_t now = (c < 3) ? TCNT3 : TCNT1;

	if ((int16_t)(now - t) < 0) {
		return;  /* a flag left from before this compare was set: not yet */
	}

	if (!s4.high[c]) {
		/* A rising edge: counter moved on; fall after SERVO_HIGH. */
		s4.high[c] = 1;
		s4.rise_at[c] = t;
		s4.rises[c]++;
		servo_com(c, COM_CLEAR);
		servo_next(c, ocr, t + SERVO_HIGH);
		return;
	}
	s4.high[c] = 0;
	uint8_t slot = (uint8_t)(s4.rises[c] - 1);
	if (slot == SERVO_SLOTS) {
		servo_com(c, COM_OFF);  /* in Q9 until the next frame's reset */
		return;
	}
	servo_com(c, COM_SET);
	servo_next(c, ocr, s4.rise_at[c] + s->dur[c][slot]);
}

ISR(TIMER3_COMPA_vect) { servo_counter_edge(0); }
ISR(TIMER3_COMPB_vect) { servo_counter_edge(1); }
ISR(TIMER3_COMPC_vect) { servo_counter_edge(2); }
ISR(TIMER1_COMPC_vect) { servo_counter_edge(3); }

static const __flash uint8_t ocie_bit[SERVO_COUNTERS] = {
	_BV(OCIE3A), _BV(OCIE3B), _BV(OCIE3C), _BV(OCIE1C),
};

/* Frame start (Timer1 compare A): reset the counters, start the active ones. */
ISR(TIMER1_COMPA_vect)
{
	uint16_t f = OCR1A;
	if (s4.pending) {
		s4.cur ^= 1;
		s4.pending = 0;
	}
	const servo_sched_t *s = &s4.sched[s4.cur];
	for (uint8_t c = 0; c < SERVO_COUNTERS; c++) {
		s4.rises[c] = 0;
		s4.high[c] = 0;
		if (s->active & (1u << c)) {
			/* Counters 0-2 count on Timer3, counter 3 on Timer1. */
			*servo_ocr(c) = f + SERVO_LEAD + (c < 3 ? s4.t3_offset : 0);
			servo_com(c, COM_SET);
			ETIMSK |= ocie_bit[c];
		} else {
			servo_com(c, COM_OFF);
			ETIMSK &= (uint8_t)~ocie_bit[c];
		}
	}
	/* Reset pulse, well before the first clock: CD4017 needs 0.3 us at
	 * 5 V; this is about 2.5 us. */
	*s4.rst_port |= s4.rst_mask;
	__builtin_avr_delay_cycles(16);
	if (!s->active) {
		/* Nothing pulses: counters held in reset, interrupts off. */
		s4.running = 0;
		TIMSK &= (uint8_t)~_BV(OCIE1A);
		return;
	}
	*s4.rst_port &= (uint8_t)~s4.rst_mask;
	OCR1A = f + s->frame;
}

void servo_hw_init(void)
{
	s4.running = 0;
	s4.pending = 0;
	s4.cur = 0;
	s4.sched[0].active = 0;
	/* Clock lines low, reset held high: all outputs quiet. */
	for (uint8_t c = 0; c < SERVO_COUNTERS; c++) {
		uint8_t pin = board_pin(BF_SERVO_CLK, c);
		pins_claim(pin, PIN_SERVO_CLK);
		port_io_write(PIN_PORT(pin), PIN_MASK(pin), 0);
		port_io_dir(PIN_PORT(pin), PIN_MASK(pin), PIN_MASK(pin));
	}
	uint8_t rst = board_pin(BF_SERVO_RST, 0);
	pins_claim(rst, PIN_SERVO_CLK);
	s4.rst_port = mcu_port(PIN_PORT(rst)).port;
	s4.rst_mask = PIN_MASK(rst);
	port_io_write(PIN_PORT(rst), s4.rst_mask, s4.rst_mask);
	port_io_dir(PIN_PORT(rst), s4.rst_mask, s4.rst_mask);
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
		s4.t3_offset = t3 - t1;
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

void servo_hw_apply(const uint16_t *widths_us)
{
	s4.pending = 0;  /* the frame interrupt must not take it half written */
	servo_sched_t *s = &s4.sched[s4.cur ^ 1];
	uint16_t frame = SERVO_FRAME;
	s->active = 0;
	for (uint8_t c = 0; c < SERVO_COUNTERS; c++) {
		uint16_t total = SERVO_LEAD + SERVO_HIGH + 16;
		for (uint8_t k = 0; k < SERVO_SLOTS; k++) {
			uint16_t us = widths_us[c * SERVO_SLOTS + k];
			uint16_t d = SERVO_GAP;
			if (us) {
				d = (uint16_t)(((uint32_t)us * (SERVO_TICK_HZ / 100UL) + 5000UL) / 10000UL);
				s->active |= (uint8_t)(1u << c);
			}
			s->dur[c][k] = d;
			total = (uint16_t)(total + d);
		}
		if ((s->active & (1u << c)) && total > frame) {
			frame = total;
		}
	}
	s->frame = frame;
	ATOMIC_BLOCK(ATOMIC_RESTORESTATE) {
		if (s4.running) {
			s4.pending = 1;
		} else if (s->active) {
			s4.cur ^= 1;
			s4.running = 1;
			OCR1A = TCNT1 + 256;
			TIMSK |= _BV(OCIE1A);
		}
	}
}
