/*
 * Servo pulses on ordinary port pins (M32-D: one pin per channel).
 *
 * Channel n's pulse starts about SERVO_SLOT * n cycles into each 20 ms frame,
 * so at most a few pulses overlap. Where an edge would come within SERVO_GAP
 * cycles of another channel's edge, the schedule moves that channel's whole
 * pulse a little (its width and period stay exact): the interrupt needs that
 * much time between two edges to make each at its cycle. Every edge is
 * written by the Timer2 compare interrupt at an exact CPU cycle: Timer2
 * (clk/8) wakes the interrupt about SERVO_LEAD cycles early (more than any
 * other interrupt plus this one's entry can delay it), the interrupt waits on
 * Timer2 until the edge is SERVO_FINE cycles away and then on Timer0 (clk/1,
 * free running) for the edge's cycle. The edges' error is the few cycles of
 * that last loop, whatever else the firmware is doing.
 *
 * The schedule (edges sorted by time) is built in the main loop when widths
 * change, into the buffer the interrupt is not using, and taken over at the
 * next frame boundary: a frame never mixes old and new widths.
 */
#include "drivers/servo_hw.h"

#include <avr/interrupt.h>
#include <avr/io.h>
#include <util/atomic.h>

#include "board.h"
#include "drivers/drv_servo.h"
#include "firmware/board_pins.h"
#include "firmware/pins.h"
#include "firmware/port_io.h"

#define SERVO_FRAME  147456UL  /* 20 ms at 7.3728 MHz */
#define SERVO_SLOT   8191UL    /* between channel starts: 1.111 ms */
#define SERVO_LEAD   480       /* wake-up before an edge, cycles */
#define SERVO_NEAR   (SERVO_LEAD + 80)  /* closer than this: wait in place */
#define SERVO_FINE   96        /* last stretch, waited on Timer0 */
#define SERVO_EDGES  (2 * SERVO_CHANNELS)
#define SERVO_FALL   0x80      /* edge code: channel | SERVO_FALL | SERVO_LONG */
#define SERVO_LONG   0x40      /* the edge's delta is 65536 cycles more */
#define SERVO_CHAN   0x1F      /* the edge code's channel */
#define SERVO_GAP    400       /* least distance between two edges, cycles */
#define SERVO_SHIFT  32        /* unit of a channel's move, cycles */
#define SERVO_MOVES  96        /* most units a channel moves either way */

_Static_assert(SERVO_SLOT * (SERVO_CHANNELS - 1) + SERVO_SHIFT * SERVO_MOVES + 18432UL + 1000UL
	       < SERVO_FRAME, "the last channel's longest pulse ends inside the frame");

/* No two edges of a frame are 131072 cycles apart (SERVO_LONG covers 17
 * bits): the latest start is the last channel's, moved late. */
_Static_assert(SERVO_SLOT * (SERVO_CHANNELS - 1) + SERVO_SHIFT * SERVO_MOVES < 0x20000UL,
	       "a delta fits 16 bits and SERVO_LONG");
_Static_assert(SERVO_CHANNELS <= SERVO_CHAN + 1, "a channel fits the edge code");

typedef struct {
	uint8_t n;                        /* edges in this frame */
	uint8_t edge[SERVO_EDGES];        /* sorted by time */
	uint16_t delta[SERVO_EDGES];      /* cycles after the edge before (the
					   * first: after the frame's start),
					   * + 65536 with SERVO_LONG */
} servo_sched_t;

static struct {
	servo_sched_t sched[2];
	volatile uint8_t active;     /* sched[] the interrupt runs */
	volatile uint8_t pending;    /* the other one is newer */
	volatile uint8_t running;
	uint8_t next;                /* next edge of the active schedule */
	uint32_t frame;              /* Timer0 cycle of the frame's start */
	uint32_t target;             /* Timer0 cycle of the next edge */
	volatile uint16_t wraps;     /* Timer2 overflows */
	uint8_t t0_offset;           /* TCNT0 - 8 * TCNT2, measured at start */
	int8_t move[SERVO_CHANNELS]; /* each channel's place: SERVO_SHIFTs off its slot */
	uint16_t width[SERVO_CHANNELS];  /* cycles, as last planned; 0 = off */
} sv;

/* Each channel's pin (PIN_ID), from the board's pin map. */
static uint8_t servo_pin[SERVO_CHANNELS];

static const __flash uint8_t port_addr[] = {
	_SFR_MEM_ADDR(PORTA), _SFR_MEM_ADDR(PORTB), _SFR_MEM_ADDR(PORTC), _SFR_MEM_ADDR(PORTD),
};
static const __flash uint8_t line_mask[8] = { 1, 2, 4, 8, 16, 32, 64, 128 };

/* Frame offset of each channel's pulse start. */
static const __flash uint32_t slot_start[SERVO_CHANNELS] = {
#define S(n) SERVO_SLOT * (n)
	S(0), S(1), S(2), S(3), S(4), S(5), S(6), S(7),
	S(8), S(9), S(10), S(11), S(12), S(13), S(14), S(15),
#undef S
};
_Static_assert(SERVO_CHANNELS == 16, "slot_start lists 16 channels");

/* Timer2 ticks (8 cycles) as a 16-bit count: edges are never more than a
 * frame (18432 ticks) ahead, so 16-bit differences order them. */
static uint16_t servo_ticks(void)
{
	uint16_t w = sv.wraps;
	uint8_t t = TCNT2;
	if ((TIFR & _BV(TOV2)) && t < 128) {
		w++;  /* an overflow not yet counted (interrupts are off) */
	}
	return (uint16_t)(w << 8 | t);
}

/* Ticks from now until `cycle`. */
static int16_t servo_ticks_to(uint32_t cycle)
{
	return (int16_t)((uint16_t)(cycle >> 3) - servo_ticks());
}

/* Arms Timer2 to wake SERVO_LEAD cycles before sv.target; false if that is
 * too close: the caller then waits for the edge in place. The compare fires
 * once per Timer2 wrap; the interrupt ignores the wraps before the edge's. */
static bool servo_arm(void)
{
	if (servo_ticks_to(sv.target) < SERVO_NEAR / 8) {
		return false;
	}
	OCR2 = (uint8_t)((sv.target - SERVO_LEAD) >> 3);
	return true;
}

ISR(TIMER2_OVF_vect)
{
	sv.wraps++;
}

ISR(TIMER2_COMP_vect)
{
	if (!sv.running || servo_ticks_to(sv.target) > SERVO_NEAR / 8) {
		return;  /* an earlier wrap, or a stale flag */
	}
	for (;;) {
		const servo_sched_t *s = &sv.sched[sv.active];
		uint8_t e = s->edge[sv.next];
		uint8_t pin = servo_pin[e & SERVO_CHAN];
		volatile uint8_t *reg = (volatile uint8_t *)(uint16_t)port_addr[PIN_PORT(pin)];
		uint8_t mask = line_mask[pin & 7];
		uint8_t lo = (uint8_t)(sv.target + sv.t0_offset);
		uint8_t and_mask = (e & SERVO_FALL) ? (uint8_t)~mask : 0xFF;
		uint8_t or_mask = (e & SERVO_FALL) ? 0 : mask;
		uint16_t fine_from = (uint16_t)((sv.target - SERVO_FINE) >> 3);

		/* Near the edge on Timer2, then to its cycle on Timer0; the write
		 * takes the same instructions for rising and falling edges. */
		/* Already past the edge (it should not happen): make it now rather
		 * than wait for Timer0 to come round again. */
		if ((int16_t)(fine_from - servo_ticks()) > -(SERVO_FINE / 8)) {
			while ((int16_t)(fine_from - servo_ticks()) > 0) {
			}
			/* 4 cycles a turn (C made it 8): edges within 3 cycles. */
			__asm__ __volatile__(
				"1:	in __tmp_reg__, %[tcnt]\n"
				"	sub __tmp_reg__, %[lo]\n"
				"	brmi 1b\n"
				:
				: [tcnt] "I" (_SFR_IO_ADDR(TCNT0)), [lo] "r" (lo));
		}
		*reg = (uint8_t)((*reg & and_mask) | or_mask);

		if (++sv.next == s->n) {
			/* Frame done: take a newer schedule over, start the next. */
			sv.next = 0;
			sv.frame += SERVO_FRAME;
			sv.target = sv.frame;
			if (sv.pending) {
				sv.active ^= 1;
				sv.pending = 0;
				s = &sv.sched[sv.active];
				if (s->n == 0) {
					sv.running = 0;
					TIMSK &= (uint8_t)~_BV(OCIE2);
					return;
				}
			}
		}
		sv.target += s->delta[sv.next];
		if (s->edge[sv.next] & SERVO_LONG) {
			sv.target += 0x10000;
		}
		if (servo_arm()) {
			return;
		}
	}
}

void servo_hw_init(void)
{
	for (uint8_t ch = 0; ch < SERVO_CHANNELS; ch++) {
		servo_pin[ch] = board_pin(BF_SERVO, ch);
	}
	sv.running = 0;
	sv.pending = 0;
	sv.active = 0;
	sv.sched[0].n = 0;
	/* Timer0 counts every cycle, Timer2 every 8th; both run free. */
	TCCR0 = _BV(CS00);
	TCCR2 = _BV(CS21);
	TIMSK |= _BV(TOIE2);
	/* Edge times are planned on Timer2 and met on Timer0: how far apart
	 * the two count only shifts the last wait's window (by up to 7 cycles,
	 * Timer2's tick), never an edge's place relative to the others. */
	ATOMIC_BLOCK(ATOMIC_RESTORESTATE) {
		uint8_t t0 = TCNT0;
		uint8_t t2 = TCNT2;
		sv.t0_offset = (uint8_t)(t0 - (uint8_t)(t2 << 3));
	}
}

bool servo_hw_can_claim(uint8_t ch)
{
	return pins_can_claim(board_pin(BF_SERVO, ch), PIN_SERVO);
}

bool servo_hw_claim(uint8_t ch)
{
	uint8_t pin = board_pin(BF_SERVO, ch);
	if (!pins_claim(pin, PIN_SERVO)) {
		return false;
	}
	port_io_write(PIN_PORT(pin), PIN_MASK(pin), 0);
	port_io_dir(PIN_PORT(pin), PIN_MASK(pin), PIN_MASK(pin));
	return true;
}

void servo_hw_release(uint8_t ch)
{
	pins_release(board_pin(BF_SERVO, ch), PIN_SERVO);
}

/* Cycles for a width in microseconds, rounded to the nearest: us * 7.3728
 * as a 16.16 fixed-point product (a division took 600 cycles a channel). */
#define SERVO_CYCLES_PER_US_Q16 ((uint32_t)((F_CPU * 65536ULL + 500000ULL) / 1000000ULL))
static uint16_t servo_cycles(uint16_t us)
{
	return (uint16_t)(((uint32_t)us * SERVO_CYCLES_PER_US_Q16 + 32768UL) >> 16);
}

/* Edge times in the planning are kept in 8-cycle units, 16 bits: a frame is
 * 18432 of them, and edges SERVO_GAP apart stay apart. */
#define SERVO_GAP8 (SERVO_GAP / 8)

/* Whether an edge at `t8` keeps SERVO_GAP from the edges in `at8`, except
 * those of channel `self`. */
static bool servo_clear_of(uint16_t t8, const uint16_t *at8, const uint8_t *edge, uint8_t n,
			   uint8_t self)
{
	for (uint8_t i = 0; i < n; i++) {
		int16_t d = (int16_t)(t8 - at8[i]);
		if ((edge[i] & SERVO_CHAN) != self && d < SERVO_GAP8 && d > -SERVO_GAP8) {
			return false;
		}
	}
	return true;
}

void servo_hw_apply(const uint16_t *widths_us)
{
	sv.pending = 0;  /* the interrupt must not take the buffer half written */
	servo_sched_t *s = &sv.sched[sv.active ^ 1];
	uint16_t at8[SERVO_EDGES];
	uint16_t *width = sv.width;
	uint16_t changed = 0;
	uint8_t n = 0;

	/* Every pulsing channel at its last place: a write changes few, and
	 * only the changed ones are placed again. */
	for (uint8_t ch = 0; ch < SERVO_CHANNELS; ch++) {
		uint16_t w = widths_us[ch] ? servo_cycles(widths_us[ch]) : 0;
		if (w != width[ch]) {
			width[ch] = w;
			changed |= (uint16_t)(1u << ch);
		}
		if (w) {
			uint32_t rise = slot_start[ch] + (int32_t)sv.move[ch] * SERVO_SHIFT;
			s->edge[n] = ch;
			at8[n++] = (uint16_t)(rise >> 3);
			s->edge[n] = ch | SERVO_FALL;
			at8[n++] = (uint16_t)((rise + w) >> 3);
		}
	}
	/* A changed channel whose edges come too close to another's moves:
	 * tries 0, +1, -1, +2, ... SERVO_SHIFTs from its slot (never before
	 * the frame's start), its width and period unchanged. The others were
	 * clear of each other already. */
	for (uint8_t i = 0; i < n; i += 2) {
		uint8_t ch = s->edge[i];
		if (!(changed & (1u << ch))) {
			continue;
		}
		for (int16_t k = 0; k <= 2 * SERVO_MOVES; k++) {
			int8_t move = (int8_t)((k & 1) ? -(k + 1) / 2 : k / 2);
			int32_t r = (int32_t)slot_start[ch] + (int32_t)move * SERVO_SHIFT;
			uint16_t r8 = (uint16_t)(r >> 3);
			uint16_t f8 = (uint16_t)((r + width[ch]) >> 3);
			if (r >= 0 && servo_clear_of(r8, at8, s->edge, n, ch)
			    && servo_clear_of(f8, at8, s->edge, n, ch)) {
				sv.move[ch] = move;
				at8[i] = r8;
				at8[i + 1] = f8;
				break;
			}
		}
	}
	/* Insertion sort by time: at most 32 edges. */
	for (uint8_t i = 1; i < n; i++) {
		uint8_t e = s->edge[i];
		uint16_t t = at8[i];
		uint8_t j = i;
		while (j > 0 && at8[j - 1] > t) {
			s->edge[j] = s->edge[j - 1];
			at8[j] = at8[j - 1];
			j--;
		}
		s->edge[j] = e;
		at8[j] = t;
	}
	/* Exact cycles from here on: each edge after the one before. */
	uint32_t prev = 0;
	for (uint8_t i = 0; i < n; i++) {
		uint8_t ch = s->edge[i] & SERVO_CHAN;
		uint32_t t = slot_start[ch] + (int32_t)sv.move[ch] * SERVO_SHIFT;
		if (s->edge[i] & SERVO_FALL) {
			t += width[ch];
		}
		/* Channels far apart: up to 125937 cycles between two edges. */
		if (t - prev > 0xFFFF) {
			s->edge[i] |= SERVO_LONG;
		}
		s->delta[i] = (uint16_t)(t - prev);
		prev = t;
	}
	s->n = n;

	ATOMIC_BLOCK(ATOMIC_RESTORESTATE) {
		if (sv.running) {
			sv.pending = 1;
		} else if (n) {
			/* Start: the first frame begins a little from now. */
			sv.active ^= 1;
			sv.next = 0;
			sv.frame = ((uint32_t)servo_ticks() << 3) + 4096;
			sv.target = sv.frame + s->delta[0];
			if (s->edge[0] & SERVO_LONG) {
				sv.target += 0x10000;
			}
			servo_arm();
			sv.running = 1;
			/* (No TIFR write: simavr 1.6 clears every flag on one.) */
			TIMSK |= _BV(OCIE2);
		}
	}
}
