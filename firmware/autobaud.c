/*
 * BAUD=auto: the line's rate found from the PC's preamble of 0x0D
 * characters (docs/protocol.md, "Autobaud", also the design).
 *
 * 0x0D in 8N1 is, in bit times: low 1 (start), high 1, low 1, high 2,
 * low 4, then the stop bit. The RXD pin is timed by counting loop
 * iterations of a known cycle count (no timer: the M32-D's three are the
 * servos', the motors' and the time base's), with interrupts on, so the drivers are never
 * disturbed; an interrupt can only shorten a measured run, and a frame
 * that no longer fits the pattern is simply not taken.
 *
 *   DETECT  the pin's runs are recorded from a falling edge until the line
 *           is quiet for AB_QUIET (6.7 ms; the host waits 20 ms after its
 *           preamble); a record with two frames in a row that last nine
 *           bits of the same rate, one of them 0x0D's shape,
 *           gives the rate: UBRR is set and the receiver turned on while
 *           the line is quiet, so it starts in step with the next start bit;
 *   FRESH   no good request yet: the pin is still recorded whenever the main
 *           loop is idle (received bytes wait in the ring), and a preamble
 *           at another rate moves the rate (noise that looked like a
 *           preamble locked a wrong one); one frame with FE sends it back
 *           to DETECT;
 *   TALK    a request parsed without error proves the rate: only AB_FE_RUN
 *           frames with FE in a row (no good frame between) send it back
 *           to DETECT.
 * A new rate (uart_line_poll gives 1) makes the front end drop what the
 * receiver took at the old one and the line the parser holds.
 */
#include "firmware/uart_line.h"

#include <avr/io.h>
#include <string.h>
#include <avr/wdt.h>
#include <util/atomic.h>

#include "board.h"
#include "firmware/board_pins.h"
#include "firmware/flash.h"
#include "firmware/mcu.h"

/* The preamble is over when RXD stays high this long (iterations of 6
 * cycles: 6.7 ms, 16 bit times at 2400 baud; a host waits at least 20 ms),
 * so the USART starts on an idle line, in step with the next start bit.
 * Low this long is a break (a 0x00 at 2400 baud is 4608 iterations). */
#define AB_QUIET 8192
/* Runs kept of a record (up to five per character; stack bytes x2): the
 * eight 0x0D of a preamble are 47. */
#define AB_MAX_RUNS 64
/* Framing errors in a row that end a proven rate. */
#define AB_FE_RUN 3

/* RXD from the board's pin map: its PINx must be in the I/O space the
 * bit-test instructions reach (ports A-D on both MCUs). */
#define AB_RXD_BIT(port, bit, fn, index) +((BF_##fn == BF_UART_RX) ? (bit) : 0)
#define AB_RXD_PORT(port, bit, fn, index) +((BF_##fn == BF_UART_RX) ? (port) : 0)
enum {
	AB_RX_BIT = 0 BOARD_PINS(AB_RXD_BIT),
	AB_RX_PORT = 0 BOARD_PINS(AB_RXD_PORT),
	AB_PIN_IO = _SFR_IO_ADDR(PINA) - 3 * (AB_RX_PORT - 'A'),
};
_Static_assert(AB_RX_PORT >= 'A' && AB_RX_PORT <= 'D', "RXD on ports A-D");
_Static_assert(_SFR_IO_ADDR(PIND) == _SFR_IO_ADDR(PINA) - 9, "PINA..PIND 3 apart");

/* Cycles of one counting iteration (sbic/sbis skipping 2, adiw 2, brcc 2)
 * and of the step from one run to the next in ab_scan. */
#define AB_LOOP_CYCLES 6
#define AB_STEP_CYCLES 12
/* A run's counter counts its cycles (AB_LOOP_CYCLES an iteration) from
 * AB_START, where AB_QUIET iterations carry out of 16 bits: a stored run
 * is AB_START + its cycles but the step to the next. */
#define AB_START (0x10000L - AB_QUIET * (long)AB_LOOP_CYCLES)
_Static_assert(AB_START > 0, "AB_QUIET iterations carry out of 16 bits");
_Static_assert(AB_MAX_RUNS % 2 == 0, "the ring wraps after a high run");
/* A run's length in cycles from what ab_scan stored, the step to the next
 * run included. */
#define AB_CYCLES(stored) ((uint16_t)((stored) - AB_START + AB_STEP_CYCLES))
/* Cycles from which a run is longer than any run of a 0x0D (4 bit times
 * at 2400 baud are 12288): about 4000 iterations, a whole high byte (one
 * compare). */
#define AB_LONG 0x5E00

/* The rates as UBRR + 1 (F_CPU / 16 / rate): a bit lasts 16 times that
 * many cycles; all exact at 7.3728 MHz. */
#define AB_RATE(r) (uint8_t)(F_CPU / (16UL * (r))),
#define AB_EXACT(r) _Static_assert(F_CPU % (16UL * (r)) == 0 && F_CPU / (16UL * (r)) <= 255, \
				   "UBRR exact and 8-bit for " #r);
ORFA_BAUD_RATES(AB_EXACT)

static const ORFA_FLASH uint8_t ab_rates[] = { ORFA_BAUD_RATES(AB_RATE) };
#define AB_NRATES (sizeof(ab_rates) / sizeof(ab_rates[0]))

/* The runs of two frames with the high run between them (stop bit and
 * any gap). */
#define AB_PAIR 11
/* The states, each the number of frames with FE in a row that send it
 * back to detection (the receiver is off in AB_DETECT). A good request ORs
 * AB_PROVEN in: AB_FRESH becomes AB_TALK; in detection, which rate 0
 * tells, the state is not read (the receiver is off) until ab_line sets it
 * again, and it never becomes AB_TALK. */
enum { AB_DETECT = 0, AB_FRESH = 1, AB_PROVEN = 2, AB_TALK = AB_FE_RUN };
_Static_assert(AB_TALK == (AB_FRESH | AB_PROVEN) && AB_TALK != (AB_DETECT | AB_PROVEN),
	       "a proven fresh rate talks; detection does not");

static struct {
	uint8_t state;
	uint8_t rate;		/* UBRR + 1 of the rate in use, 0 in AB_DETECT */
	volatile uint8_t lost;	/* set by the receive interrupt */
	uint8_t fe_run;
} autobaud;

/*
 * Two frames in a row from P (P[0] low) last 9 bit times (start bit to
 * stop bit) of the same rate, with at least half a bit between them, and
 * one of them has 0x0D's shape: that rate (UBRR + 1), or 0. One frame may
 * be bent: an interrupt that runs while a run is timed shortens it (the
 * drivers' interrupts stay on), which the 1/8 tolerance of a frame's length
 * absorbs but a single run's may not. In assembly for its size (about 170
 * bytes less than the compiler's), as C:
 *
 *   k = rate(P), the table's rate whose window holds total(P), else 0;
 *   if (!k || cycles(P[5]) < 8 k || !window(total(P + 6), k)) return 0;
 *   return (shape(P, k) || shape(P + 6, k)) ? k : 0;
 *
 *   total(Q)     the five runs' cycles from Q; none when a run is AB_LONG
 *                or more, or the sum so far AB_NINE_MAX or more (it never
 *                wraps; no rate's frame is that long);
 *   window(t, k) nine bit times within 1/8: 126 k <= t <= 162 k, the
 *                rates' windows apart, so a frame in K's is of no other;
 *   shape(Q, k)  each run within a third of a bit and half a counting
 *                iteration (floor(16 k / 3) + 3 cycles) of 0x0D's 1 1 1 2
 *                4 bits: a run is measured to an iteration (6 cycles),
 *                which at 460800 (16 cycles a bit) is more than a third of
 *                a bit.
 */
#define AB_NINE_MAX 0xA200
_Static_assert(AB_NINE_MAX > 162L * 255 && AB_NINE_MAX + (long)AB_LONG <= 0x10000L &&
	       (AB_NINE_MAX & 0xFF) == 0 && (AB_LONG & 0xFF) == 0,
	       "above every rate's frame, no wrap, one compare each");
static inline __attribute__((always_inline)) uint8_t ab_check(const uint16_t *p)
{
	uint8_t k;
	uint8_t j;
	uint16_t c;
	uint16_t s;
	uint16_t tol;
	const ORFA_FLASH uint8_t *z;

	asm("	rcall 20f\n\t"		/* s = total(P), X = P + 10 */
	    "	brcc 9f\n\t"
	    "	ldi %A[z], lo8(%[rates])\n\t"
	    "	ldi %B[z], hi8(%[rates])\n"
	    "1:	cpi %A[z], lo8(%[rates] + %[nrates])\n\t"
	    "	breq 9f\n\t"
	    "	lpm %[k], %a[z]+\n\t"
	    "	rcall 30f\n\t"
	    "	brcs 1b\n\t"
	    /* P[5], the high run between the frames, at least half a bit */
	    "	ld %A[c], %a[x]+\n\t"
	    "	ld %B[c], %a[x]+\n\t"
	    "	subi %A[c], lo8(%[off])\n\t"
	    "	sbci %B[c], hi8(%[off])\n\t"
	    "	ldi %[j], 8\n\t"
	    "	mul %[k], %[j]\n\t"
	    "	cp %A[c], r0\n\t"
	    "	cpc %B[c], r1\n\t"
	    "	brlo 9f\n\t"
	    "	rcall 20f\n\t"		/* s = total(P + 6), X = P + 22 */
	    "	brcc 9f\n\t"
	    "	rcall 30f\n\t"
	    "	brcs 9f\n\t"
	    "	sbiw %[x], 22\n\t"
	    "	movw %[z], %[x]\n\t"
	    "	rcall 40f\n\t"		/* shape(P, k) */
	    "	brtc 10f\n\t"
	    "	adiw %[z], 2\n\t"
	    "	rcall 40f\n\t"		/* shape(P + 6, k) */
	    "	brtc 10f\n"
	    "9:	clr %[k]\n"
	    "10:	clr __zero_reg__\n\t"
	    "	rjmp 99f\n"
	    /* total(X): into s, X past the five runs; C clear: none */
	    "20:	ldi %[j], 5\n\t"
	    "	clr %A[s]\n\t"
	    "	clr %B[s]\n"
	    "21:	ld %A[c], %a[x]+\n\t"
	    "	ld %B[c], %a[x]+\n\t"
	    "	subi %A[c], lo8(%[off])\n\t"
	    "	sbci %B[c], hi8(%[off])\n\t"
	    "	cpi %B[c], hi8(%[lng])\n\t"
	    "	brsh 22f\n\t"
	    "	add %A[s], %A[c]\n\t"
	    "	adc %B[s], %B[c]\n\t"
	    "	cpi %B[s], hi8(%[max])\n\t"
	    "	brsh 22f\n\t"
	    "	dec %[j]\n\t"
	    "	brne 21b\n"
	    "22:	ret\n"
	    /* window(s, k): C set when out */
	    "30:	ldi %[j], 126\n\t"
	    "	mul %[k], %[j]\n\t"
	    "	movw %[c], %[s]\n\t"
	    "	sub %A[c], r0\n\t"
	    "	sbc %B[c], r1\n\t"
	    "	ldi %[j], 36\n\t"
	    "	mul %[k], %[j]\n\t"
	    "	cp r0, %A[c]\n\t"
	    "	cpc r1, %B[c]\n\t"
	    "	ret\n"
	    /* shape(Z, k): T set when a run is off; Z past the five runs.
	     * X: the run's bits, 16 k (doubled for the last two); tol:
	     * 5 k + k / 3 + 3 (k / 3 as k * 171 >> 9, exact to 255); s: 2 tol */
	    "40:	ldi %[j], 16\n\t"
	    "	mul %[k], %[j]\n\t"
	    "	movw %[x], r0\n\t"
	    "	ldi %[j], 171\n\t"
	    "	mul %[k], %[j]\n\t"
	    "	mov %A[tol], r1\n\t"
	    "	lsr %A[tol]\n\t"
	    "	subi %A[tol], lo8(-%[half])\n\t"
	    "	clr %B[tol]\n\t"
	    "	ldi %[j], 5\n\t"
	    "	mul %[k], %[j]\n\t"
	    "	add %A[tol], r0\n\t"
	    "	adc %B[tol], r1\n\t"
	    "	movw %[s], %[tol]\n\t"
	    "	lsl %A[s]\n\t"
	    "	rol %B[s]\n\t"
	    "	clt\n"
	    "41:	cpi %[j], 3\n\t"
	    "	brsh 42f\n\t"
	    "	lsl %A[x]\n\t"
	    "	rol %B[x]\n"
	    "42:	ld %A[c], %a[z]+\n\t"
	    "	ld %B[c], %a[z]+\n\t"
	    "	subi %A[c], lo8(%[off])\n\t"
	    "	sbci %B[c], hi8(%[off])\n\t"
	    "	sub %A[c], %A[x]\n\t"
	    "	sbc %B[c], %B[x]\n\t"
	    "	add %A[c], %A[tol]\n\t"
	    "	adc %B[c], %B[tol]\n\t"
	    "	cp %A[s], %A[c]\n\t"
	    "	cpc %B[s], %B[c]\n\t"
	    "	brcc 43f\n\t"
	    "	set\n"
	    "43:	dec %[j]\n\t"
	    "	brne 41b\n\t"
	    "	ret\n"
	    "99:"
	    : [x] "+x" (p), [z] "=&z" (z), [k] "=&r" (k), [j] "=&d" (j), [c] "=&d" (c),
	      [s] "=&d" (s), [tol] "=&d" (tol)
	    : [rates] "i" (ab_rates), [nrates] "n" (AB_NRATES),
	      [off] "n" (AB_START - AB_STEP_CYCLES), [lng] "n" (AB_LONG),
	      [max] "n" (AB_NINE_MAX), [half] "n" (AB_LOOP_CYCLES / 2)
	    : "r0", "memory");
	return k;
}

/* The receiver on at rate R (UBRR + 1), the rate fresh; R 0: off, back to
 * detection. One body for both (10 B less than two). */
static void __attribute__((noinline)) ab_line(uint8_t r)
{
	uint8_t state = AB_DETECT;

	ATOMIC_BLOCK(ATOMIC_RESTORESTATE) {
		/* the transmitter's bits kept: UDRIE may be set (a reply going
		 * out) */
		uint8_t ucsrb = MCU_UCSRB & (uint8_t)~(_BV(RXEN) | _BV(RXCIE));

		if (r) {
			/* UBRRH: 0 from reset (every rate's UBRR is 8-bit) */
			MCU_UBRRL = (uint8_t)(r - 1);
			ucsrb |= _BV(RXEN) | _BV(TXEN) | _BV(RXCIE);
			state = AB_FRESH;
		}
		MCU_UCSRB = ucsrb;
		/* Framing errors seen so far were at the old rate. */
		autobaud.lost = 0;
		autobaud.fe_run = 0;
	}
	autobaud.rate = r;
	autobaud.state = state;
}

/*
 * Record the line once: wait up to AB_QUIET iterations (6.7 ms, the main
 * loop then comes round) for RXD to fall, then time the runs, low and
 * high in turn, into the ring of AB_MAX_RUNS from RUN[1], until RXD stays
 * high for AB_QUIET iterations
 * (the line is quiet: that high run is not stored) or low as long (a
 * break). Every run's counter counts its cycles from AB_START, so that its
 * carry is the quiet or the break. The ring keeps the last AB_MAX_RUNS runs before the end,
 * however long the line was busy. One block of assembly so that every step
 * from one run to the next costs the same (AB_STEP_CYCLES).
 *
 * If the runs before the quiet hold two 0x0D in a row at one rate, that
 * rate (UBRR + 1); the last such pair wins (a fresh run at another rate
 * replaces an earlier one). 0: no rate (also after 6.7 ms without an
 * edge).
 */
static uint8_t __attribute__((noinline)) ab_scan(void)
{
	/* the ring, and its first AB_PAIR - 1 runs again after it: a pair
	 * across its end is read in one piece; before it, the slot of the
	 * wait for the first edge */
	uint16_t run[1 + AB_MAX_RUNS + AB_PAIR - 1];
	uint16_t *p = run;
	uint8_t left = AB_MAX_RUNS + 2;
	uint8_t wrapped = 0;
	uint16_t n;

	wdt_reset();
	/* The wait for the first edge is a high run's (its end stored in
	 * run[0], left counting it): RXD high the quiet's length first ends
	 * the record with no runs. */
	asm volatile("4:	ldi %A[n], lo8(%[q])\n\t"
		     "	ldi %B[n], hi8(%[q])\n"
		     "5:	sbis %[pin], %[bit]\n\t"
		     "	rjmp 6f\n\t"
		     "	adiw %[n], %[it]\n\t"
		     "	brcc 5b\n\t"
		     "	rjmp 9f\n"
		     "6:	st %a[p]+, %A[n]\n\t"
		     "	st %a[p]+, %B[n]\n\t"
		     "	subi %[left], 2\n\t"
		     "	brne 1f\n\t"
		     "	movw %[p], %[base]\n\t"
		     "	ldi %[left], %[max]\n\t"
		     "	ldi %[wr], 1\n\t"
		     /* the line busy a ring's runs: progress, the watchdog
		      * fed (a flood that never left the line quiet kept
		      * this loop 256 ms and reset the board, again and
		      * again); this step a cycle longer */
		     "	wdr\n"
		     "1:	ldi %A[n], lo8(%[q])\n\t"
		     "	ldi %B[n], hi8(%[q])\n"
		     "2:	sbic %[pin], %[bit]\n\t"
		     "	rjmp 3f\n\t"
		     "	adiw %[n], %[it]\n\t"
		     "	brcc 2b\n\t"
		     /* a break: no runs, nothing wrapped */
		     "	ldi %[left], %[max]\n\t"
		     "	clr %[wr]\n\t"
		     "	rjmp 9f\n"
		     /* a low run: the ring wraps only after a high one (it
		      * holds an even number); nop and rjmp, three cycles,
		      * give this step the high run's length (its subi and
		      * brne) */
		     "3:	st %a[p]+, %A[n]\n\t"
		     "	st %a[p]+, %B[n]\n\t"
		     "	nop\n\t"
		     "	rjmp 4b\n"
		     "9:\n"
		     : [n] "=&w" (n), [p] "+&e" (p), [left] "+d" (left), [wr] "+d" (wrapped)
		     : [base] "r" (run + 1), [pin] "I" (AB_PIN_IO), [bit] "I" (AB_RX_BIT),
		       [q] "i" (AB_START), [it] "I" (AB_LOOP_CYCLES), [max] "M" (AB_MAX_RUNS)
		     : "memory");
	/* The next write position: the record ends after a low run (the
	 * quiet is high), which left does not count; so it is odd, and the
	 * newest pair's first run, AB_PAIR before it, even: a low one, as
	 * every second run back from there. 1 after a break, 255 (-1) after
	 * a quiet without an edge: no pair. */
	uint8_t next = (uint8_t)(AB_MAX_RUNS + 1 - left);
	/* the pairs: all of the ring's, or those before NEXT */
	_Static_assert(AB_PAIR % 2 == 1, "a pair from a low run ends before a low one");
	int8_t pairs = wrapped ? (AB_MAX_RUNS - AB_PAIR + 1) / 2 : (int8_t)(next - AB_PAIR + 2) >> 1;

	memcpy(run + 1 + AB_MAX_RUNS, run + 1, (AB_PAIR - 1) * sizeof(run[0]));
	/* From the newest back: the last pair wins. */
	for (uint8_t at = (uint8_t)(next - AB_PAIR); pairs > 0; pairs--, at -= 2) {
		uint8_t r = ab_check(run + 1 + (at & (AB_MAX_RUNS - 1)));

		if (r) {
			return r;
		}
	}
	return 0;
}

/* After reset the receiver is off and the state AB_DETECT: zero, as
 * static storage starts. */
_Static_assert(AB_DETECT == 0, "the state at reset is the zeroed one");
void uart_init(void)
{
}

uint8_t uart_line_poll(void)
{
	if (autobaud.lost) {
		ab_line(0);
	}
	if (autobaud.state == AB_TALK) {
		return 0;
	}
	/* One record a call. While the rate is fresh the pin is still
	 * watched (the receiver runs on): a preamble at another rate after a
	 * wrong lock (noise that looked like one) moves the rate. The bytes
	 * the receiver takes meanwhile wait in the ring. */
	uint8_t r = ab_scan();

	if (r == 0 || r == autobaud.rate) {
		/* no rate yet: round the main loop (nothing received to drop) */
		return autobaud.rate == 0;  /* detecting */
	}
	ab_line(r);
	return 1;
}

void uart_line_rx(void)
{
	if (!(MCU_UCSRA & _BV(FE))) {
		autobaud.fe_run = 0;
	} else if (++autobaud.fe_run >= autobaud.state) {
		autobaud.lost = autobaud.fe_run;  /* nonzero: one load less than 1 */
	}
}

void uart_line_confirm(void)
{
	autobaud.state |= AB_PROVEN;
}

