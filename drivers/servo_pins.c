/*
 * Servo pulses on ordinary port pins (M32-D: one pin per channel), on the
 * schedule servo_plan.c makes. The Timer2 compare interrupt writes every
 * edge at its exact CPU cycle, in three steps: Timer2 (clk/8) wakes it
 * about SERVO_LEAD cycles early, more than any other interrupt plus this
 * one's entry can delay it (the main loop's one long section with
 * interrupts off, uart_rx_flush(), does not start while the compare
 * waits: it would add to an interrupt's delay); it waits on Timer2 until the edge is SERVO_FINE
 * cycles away; then it waits on Timer0 (clk/1, free running) for the edge's
 * cycle. An edge is off by no more than the few cycles of that last loop,
 * whatever else the firmware is doing.
 *
 * The main loop plans a new schedule (edges in time order) when widths
 * change, once the write's reply is queued (servo_hw_later()), into the
 * buffer the interrupt is not running, and the interrupt
 * takes it over at the next frame boundary: a frame never mixes old and
 * new widths.
 */
#include "drivers/servo_hw.h"

#include <avr/interrupt.h>
#include <avr/io.h>
#include <util/atomic.h>

#include "board.h"
#include "drivers/drivers.h"
#include "drivers/servo_plan.h"
#include "firmware/board_pins.h"
#include "firmware/clock.h"
#include "firmware/front.h"
#include "firmware/pins.h"
#include "firmware/port_io.h"
#include "firmware/uart.h"

/* The last stretch, waited on Timer0 (its signed 8-bit compare reaches
 * 127 cycles back). The Timer2 wait's last turn can begin SERVO_HOLD_TICKS
 * + 1 ticks before this stretch and take two characters into the hold
 * (~50 cycles) before it looks at the time again (~40): with 96 that turn
 * now and then ran past the edge's cycle, and the edge came 8-13 cycles
 * late at 460800 (test_fast_rates.py::test_servo_widths_with_the_line_busy,
 * about 1 run in 4 under load); with 112, none in 200. */
#define SERVO_FINE   112
/* The receive interrupt's longest run (BOARD_RX_BURST characters, ~85
 * cycles each, and its entry), and the interrupt's own from the wake-up to
 * the last stretch, cycles: the lead allows for both. */
#define SERVO_RX_CHAR 85
#define SERVO_ENTRY   300
/* The lead: the receive interrupt's run and the wake-up's own, a whole
 * number of Timer2 ticks, and never less than the clock's tick needs (480,
 * as before the fast rates; BOARD_SERVO_LEAD_MIN): 480 at 115200, 552 at
 * 230400, 640 at 460800 (600 left an edge 20 cycles late now and then in
 * tests/sim/test_fast_rates.py). Every cycle of it is the main loop's,
 * twice a channel a frame (at 640 servo streaming at 115200 fell to 97 %
 * of the wire). The I2C slave has no serial receiver: 480 (a longer
 * lead would take its cycles from the slave's longest write,
 * docs/protocol.md, the SPI exchange the gateway waits out). */
#ifdef ORFA_MODE_slave
#define SERVO_RX_ISR  0
#else
#define SERVO_RX_ISR  (BOARD_RX_BURST * SERVO_RX_CHAR + 80)
#endif
#define SERVO_LEAD_NEED ((SERVO_RX_ISR + SERVO_ENTRY + 7) / 8 * 8)
#define SERVO_LEAD (SERVO_LEAD_NEED > BOARD_SERVO_LEAD_MIN ? SERVO_LEAD_NEED : BOARD_SERVO_LEAD_MIN)
#define SERVO_NEAR   (SERVO_LEAD + 80)  /* closer than this: wait in place */
_Static_assert(SERVO_LEAD >= SERVO_RX_ISR + SERVO_ENTRY, "the lead allows a receive interrupt");
/* An edge this far away leaves time to hand on the whole hold. */
#define SERVO_FAR (SERVO_LEAD + SERVO_RX_CHAR * (UART_HOLD + 2))
/*
 * Interrupts are off from the wake-up to the edge, longer than the USART
 * holds received characters above 115200 baud (two: 320 cycles at 460800
 * baud). So the interrupt takes them into the receiver's hold
 * (front_rx_hold(), ~30 cycles with the call) as it starts, every turn of
 * its wait until SERVO_HOLD_TICKS Timer2 ticks before the last stretch (a
 * turn that holds one must end inside that stretch) and right after each
 * edge, and lets the receive interrupt hand them on (front_rx_poll()) as it
 * returns, within the next wake-up's lead. What it could not hand on goes
 * with the next receive interrupt (it hands the hold on first) or the main
 * loop's flush (uart_rx_flush()), in order, even while the interrupt sleeps
 * between frames (servo_arm()).
 */
#define SERVO_HOLD_TICKS 3

/* What the others cannot wait for while the interrupt keeps interrupts
 * off, done where it takes received characters into the hold: in the
 * gateway, that; in the I2C slave (no receiver), each driver's
 * DRV_name_WAIT(): the SPI exchange's next byte (spi_hw.h). The slave's
 * longest write (docs/protocol.md), an exchange of 57 bytes at F_CPU/128,
 * stood still for the rest of each wait that came as a byte ended, up to
 * ~700 cycles an edge: its stretch came out 60500-68600 cycles, by where
 * the edges fell among the bytes, against the gateway's wait of 69632. */
#ifdef ORFA_MODE_slave
#define X(name) DRV_##name##_WAIT();
static inline void servo_hold(void)
{
	ORFA_DRIVER_LIST
}
#undef X
#else
#define servo_hold front_rx_hold
#endif

static struct {
	servo_sched_t sched[2];
	volatile uint8_t active;     /* sched[] the interrupt runs */
	volatile uint8_t pending;    /* the other one is newer */
	volatile uint8_t running;
	uint8_t marked;              /* widths changed since the last plan */
	const servo_edge_t *edge;    /* the next edge, in sched[active] */
	const servo_edge_t *end;     /* past sched[active]'s last edge */
	uint16_t frame;              /* Timer2 tick of the frame's start */
	uint16_t target;             /* Timer2 tick of the next edge */
	uint8_t target_t0;           /* TCNT0 at the next edge's cycle */
	uint8_t t0_offset;           /* TCNT0 - 8 * TCNT2, measured at start */
} pulses;

/* Each channel's pin (PIN_ID), from the board's pin map, which has
 * channels 0..SERVO_CHANNELS-1 once each. */
static uint8_t servo_pin[SERVO_CHANNELS];
#define SERVO_PIN_ROW(port, line, fn, index) +(BF_##fn == BF_SERVO && (index) < SERVO_CHANNELS)
_Static_assert((0 BOARD_PINS(SERVO_PIN_ROW)) == SERVO_CHANNELS, "a pin for every servo channel");
#undef SERVO_PIN_ROW

/*
 * A channel turned off gives its line back at once (to GPIO, or to the
 * stopped motor that lent it, which a PWM may start by the next request),
 * while the interrupt runs the old schedule, the channel's edges in it, up
 * to the frame a plan without it starts. Its pin is marked SERVO_PIN_GONE
 * then (a claim takes the mark off): the interrupt writes its port back as
 * it is, never the line (its fall pulled a motor's steady PWM 255 low for
 * good, tests/sim/test_drv_motor.py). A bit pin IDs leave free (ports A-D:
 * 0..31), so no RAM; port_addr[] twice, so a marked pin's port is the same.
 */
#define SERVO_PIN_GONE 0x20
_Static_assert(PIN_ID('D', 7) < SERVO_PIN_GONE, "pin IDs leave bit 5 free");
static const __flash uint8_t port_addr[] = {
	_SFR_MEM_ADDR(PORTA), _SFR_MEM_ADDR(PORTB), _SFR_MEM_ADDR(PORTC), _SFR_MEM_ADDR(PORTD),
	_SFR_MEM_ADDR(PORTA), _SFR_MEM_ADDR(PORTB), _SFR_MEM_ADDR(PORTC), _SFR_MEM_ADDR(PORTD),
};
static const __flash uint8_t line_mask[8] = { 1, 2, 4, 8, 16, 32, 64, 128 };

/* Timer2 is shared: the time base (firmware/clock.c) runs it and counts
 * its overflows, this driver uses its compare unit (OCR2). */
_Static_assert(BOARD_CLOCK_TIMER == 2, "servo_pins.c plans edges on the time base's Timer2");
/* Frames start on a Timer2 tick: an edge's tick and Timer0 count follow
 * from its cycle in the frame with 16- and 8-bit sums. */
_Static_assert(SERVO_FRAME % 8 == 0 && SERVO_LEAD % 8 == 0 && SERVO_FINE % 8 == 0,
	       "frames, the lead and the last stretch are whole Timer2 ticks");

/*
 * Now in Timer2 ticks (8 cycles) as a 16-bit count: edges are never more
 * than a frame (18432 ticks) ahead, so 16-bit differences order them.
 *
 * Called with interrupts off (in the compare interrupt or a locked block),
 * so an overflow may be pending that the overflow interrupt has not
 * counted: it is counted here and its flag cleared. The flag is looked at
 * whatever TCNT2 reads, because the compare interrupt can run more than
 * half a wrap past an overflow while it waits in place for close edges. An
 * overflow left uncounted would make the edge every wait is for recede by
 * 256 ticks a wrap, and the wait would never end.
 */
static uint16_t servo_ticks(void)
{
	uint16_t wraps = clock_wraps;  /* read once (volatile, but interrupts are off) */
	uint8_t t = TCNT2;
	if (TIFR & _BV(TOV2)) {
		TIFR = _BV(TOV2);  /* a 1 clears that flag only */
		clock_wraps = ++wraps;
		t = TCNT2;         /* again: the first read may be from before the overflow */
	}
	return (uint16_t)(wraps << 8 | t);
}

/* Ticks from now until the next edge. The target read after the call:
 * read before it, it was kept across it in r28/r29, pushed and popped
 * (8 B, 8 cycles a look). */
static int16_t servo_ticks_left(void)
{
	uint16_t now = servo_ticks();

	return (int16_t)(pulses.target - now);
}

/* Makes `e` the next edge: its tick and Timer0 count. */
static void servo_aim(const servo_edge_t *e)
{
	uint16_t at = e->at;
	uint8_t hi = (uint8_t)(e->code >> 4) & 3;  /* the cycle's bits 16-17 */

	pulses.edge = e;
	pulses.target = (uint16_t)(pulses.frame + (uint16_t)(hi << 13) + (at >> 3));
	pulses.target_t0 = (uint8_t)((uint8_t)(pulses.frame << 3) + (uint8_t)at + pulses.t0_offset);
}

/* Arms Timer2 to wake SERVO_LEAD cycles before the next edge; false if that
 * is too close: the caller then waits for the edge in place. The compare
 * fires once per Timer2 wrap; the interrupt ignores the wraps before the
 * edge's. A wake-up a wrap or more away sleeps, the clock's overflow
 * interrupt turning the compare on again with its stale flag cleared: each
 * wrap's wake-up in between cost ~250 cycles with interrupts off, up to
 * three an edge (about 4 % of the M32-D's control loop at 230400). It is
 * turned on at the start of the wake-up's own wrap when the wake-up is
 * SERVO_WAKE_MARGIN ticks or more into it, else a wrap before (one wake-up
 * then finds its edge far): the overflow interrupt may come that late (a
 * receive interrupt, the main loop's flush after it, its own entry), and
 * the wake-up would come as late as it. */
#define SERVO_WAKE_MARGIN ((SERVO_LEAD + 256) / 8)
_Static_assert(2 * SERVO_RX_ISR + 200 <= SERVO_WAKE_MARGIN * 8,
	       "the overflow interrupt turns the compare on before its match");
static bool servo_arm(void)
{
	uint16_t now = servo_ticks();
	int16_t left = (int16_t)(pulses.target - now);

	if (left < SERVO_NEAR / 8) {
		return false;
	}
	uint16_t wake = (uint16_t)(pulses.target - SERVO_LEAD / 8);
	uint8_t from = (uint8_t)(wake >> 8);

	if ((uint8_t)wake < SERVO_WAKE_MARGIN) {
		from--;
	}
	OCR2 = (uint8_t)wake;
	if ((int8_t)(from - (uint8_t)(now >> 8)) > 0) {
		TIMSK &= (uint8_t)~_BV(OCIE2);
		clock_compare_from(from);
	}
	return true;
}

/* Lets the receive interrupt hand on what the hold keeps: all of it while
 * the next edge is SERVO_FAR away, BOARD_RX_BURST characters when it is
 * SERVO_NEAR away, nothing closer (the caller then waits for the edge in
 * place, holding). All of it goes SERVO_RX_CHUNK at a time, the edge
 * looked at again in between (servo_ticks() counting Timer2's overflow):
 * in one call, a full hold and what arrived meanwhile ran ~2250 cycles
 * with interrupts off at 460800 (~115 a character), past a Timer2 wrap,
 * and an overflow went uncounted: every edge after it a wrap (2048
 * cycles) late, one pulse that much too long. Now ~1400 cycles at most
 * between two looks; the next chunk only while the hold keeps some: a
 * turn as long as UDR had a character (~45 cycles a turn more) never
 * caught up with characters back to back at 460800 (interrupts off
 * ~11000 cycles). The cost: a chunk's call and look, the interrupt's
 * longest run with the line busy at 460800 ~3700 -> ~4600 cycles. */
#define SERVO_RX_CHUNK 12
static void servo_rx_release(void)
{
	if (SERVO_RX_ISR == 0) {
		return;  /* the I2C slave: no receiver, nothing held (~40 cycles an edge) */
	}
	int16_t left = servo_ticks_left();

	if (left > SERVO_FAR / 8) {
		while (front_rx_poll(SERVO_RX_CHUNK) && (left = servo_ticks_left()) > SERVO_FAR / 8) {
		}
		if (left > SERVO_FAR / 8) {
			return;  /* the hold empty (one call, as before, when it was) */
		}
	}
	if (left > SERVO_NEAR / 8) {
		front_rx_poll(BOARD_RX_BURST);
	}
}

static inline __attribute__((always_inline)) void servo_interrupt(void)
{
	servo_hold();
	if (!pulses.running || servo_ticks_left() > SERVO_NEAR / 8) {
		servo_rx_release();
		return;  /* an earlier wrap, or a stale flag */
	}
	for (;;) {
		const servo_edge_t *edge = pulses.edge;
		uint8_t e = edge->code;
		uint8_t pin = servo_pin[e & SERVO_CHAN];
		volatile uint8_t *reg = (volatile uint8_t *)(uint16_t)port_addr[PIN_PORT(pin)];
		uint8_t mask = line_mask[pin & 7];
		if (pin & SERVO_PIN_GONE) {
			mask = 0;  /* not the servo's line any more: left as it is */
		}
		uint8_t lo = pulses.target_t0;
		uint8_t and_mask = (e & SERVO_FALL) ? (uint8_t)~mask : 0xFF;
		uint8_t or_mask = (e & SERVO_FALL) ? 0 : mask;
		int16_t left = (int16_t)(servo_ticks_left() - SERVO_FINE / 8);

		/* Wait on Timer2 until SERVO_FINE cycles before the edge, then on
		 * Timer0 for its cycle. An edge already past (the lead time should
		 * prevent it) is written at once, not after Timer0 comes round
		 * again. */
		if (left > -(SERVO_FINE / 8)) {
			while (left > 0) {
				if (left > SERVO_HOLD_TICKS) {
					servo_hold();
				}
				left = (int16_t)(servo_ticks_left() - SERVO_FINE / 8);
			}
			/* In assembly for 4 cycles a turn, so the write comes within
			 * 3 cycles of the edge's cycle (the loop in C takes 8). */
			__asm__ __volatile__(
				"1:	in __tmp_reg__, %[tcnt]\n"
				"	sub __tmp_reg__, %[lo]\n"
				"	brmi 1b\n"
				:
				: [tcnt] "I" (_SFR_IO_ADDR(TCNT0)), [lo] "r" (lo));
		}
		/* The same instructions for a rise and a fall: both come equally
		 * long after the wait. */
		*reg = (uint8_t)((*reg & and_mask) | or_mask);
		servo_hold();

		if (++edge == pulses.end) {
			/* Frame done: take a newer schedule over, start the next. */
			pulses.frame += SERVO_FRAME / 8;
			if (pulses.pending) {
				pulses.active ^= 1;
				pulses.pending = 0;
				const servo_sched_t *s = &pulses.sched[pulses.active];
				if (s->n == 0) {
					pulses.running = 0;
					TIMSK &= (uint8_t)~_BV(OCIE2);
					clock_compare_cancel();
					front_rx_poll(FRONT_HOLD_ALL);  /* no more edges */
					return;
				}
				pulses.end = &s->edge[s->n];
			}
			edge = pulses.sched[pulses.active].edge;
		}
		/* The release before the wake-up is armed, not after: its
		 * burst (~320 cycles) after an arm at SERVO_NEAR ran past the
		 * wake-up, and the interrupt came back late for the edge (8-11
		 * cycles late at 460800). An edge the release brought closer
		 * than SERVO_NEAR is waited for in place. What reached UDR
		 * while the release ran (it hands on BOARD_RX_BURST at most
		 * when the edge is near) goes into the hold before the arm:
		 * left in UDR it waited for the arm, the return and the clock
		 * tick's interrupt, ~230 cycles, and a third character was lost
		 * now and then at 460800 (tests/sim/test_fast_rates.py's
		 * flow-rule test, 2 runs in 10). */
		servo_aim(edge);
		servo_hold();
		servo_rx_release();
		servo_hold();
		if (servo_arm()) {
			return;
		}
	}
}

ISR(TIMER2_COMP_vect)
{
	servo_interrupt();
	front_rx_held();  /* what it left in the hold, for the receive interrupt */
}

void servo_hw_init(void)
{
	board_pins_of(BF_SERVO, servo_pin);
	/* pulses: not running, nothing pending, sched[0] empty and active, as
	 * static storage starts (this runs once, after reset: 16 B of
	 * stores less) */
	/* Timer0 counts every cycle; Timer2 counts every 8th, run free by
	 * the time base (firmware/clock.c), which counts its overflows. */
	TCCR0 = _BV(CS00);
	/* Edge times are planned on Timer2 and met on Timer0: how far apart
	 * the two count only shifts the last wait's window (by up to 7 cycles,
	 * Timer2's tick), never an edge's place relative to the others. */
	ATOMIC_BLOCK(ATOMIC_RESTORESTATE) {
		uint8_t t0 = TCNT0;
		uint8_t t2 = TCNT2;
		pulses.t0_offset = (uint8_t)(t0 - (uint8_t)(t2 << 3));
	}
}

bool servo_hw_can_claim(uint8_t ch)
{
	return pins_can_claim((uint8_t)(servo_pin[ch] & ~SERVO_PIN_GONE), PIN_SERVO);
}

bool servo_hw_claim(uint8_t ch)
{
	uint8_t pin = (uint8_t)(servo_pin[ch] & ~SERVO_PIN_GONE);
	if (!pins_claim(pin, PIN_SERVO)) {
		return false;
	}
	pins_drive(pin, false);  /* output, low */
	servo_pin[ch] = pin;     /* the interrupt's edges drive it again */
	return true;
}

void servo_hw_release(uint8_t ch)
{
	uint8_t pin = servo_pin[ch];
	servo_pin[ch] = (uint8_t)(pin | SERVO_PIN_GONE);  /* first: the interrupt leaves it */
	pins_release(pin, PIN_SERVO);
}

/* The plan waits for servo_hw_later(): it compares the widths then with
 * those it planned last (servo_plan()). */
void servo_hw_apply(const uint16_t *widths_us)
{
	(void)widths_us;
	pulses.marked = 1;
}

void servo_hw_later(const uint16_t *widths_us)
{
	if (!pulses.marked) {
		return;
	}
	pulses.marked = 0;
	uint8_t newer;
	ATOMIC_BLOCK(ATOMIC_RESTORESTATE) {
		/* The interrupt must not take the buffer half written. */
		newer = pulses.pending;
		pulses.pending = 0;
	}
	/* The buffer the interrupt does not run, and the one it does (each
	 * an address, not a multiply by the schedule's size); the last plan:
	 * the buffer not taken over yet, else the running one. */
	servo_sched_t *s = &pulses.sched[1], *run = &pulses.sched[0];
	if (pulses.active) {
		s = run;
		run = &pulses.sched[1];
	}
	servo_plan(s, newer ? s : run, widths_us);
	uint8_t n = s->n;

	ATOMIC_BLOCK(ATOMIC_RESTORESTATE) {
		if (pulses.running) {
			pulses.pending = 1;
		} else if (n) {
			/* Start: the first frame begins a little from now. */
			pulses.active ^= 1;
			pulses.end = &s->edge[n];
			pulses.frame = servo_ticks() + 4096 / 8;
			servo_aim(s->edge);
			/* on, unless servo_arm() leaves it to the clock's overflow
			 * (a stale flag needs no clearing: the interrupt it wakes
			 * finds its edge far and returns); interrupts are off, so
			 * the compare waits for the arm; the first edge is never
			 * SERVO_NEAR close */
			_Static_assert(4096 > SERVO_NEAR, "a start's first edge is armed");
			TIMSK |= _BV(OCIE2);
			servo_arm();
			pulses.running = 1;
		}
	}
}
