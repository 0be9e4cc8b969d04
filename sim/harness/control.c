/*
 * control.c: the control socket and its line protocol.
 */
#define _GNU_SOURCE
#include <ctype.h>
#include <errno.h>
#include <fcntl.h>
#include <inttypes.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include "harness/control.h"
#include "harness/fault.h"
#include "harness/isr_watch.h"
#include "harness/profile.h"
#include "boards/sram.h"
#include "parts/part.h"

#define CONTROL_OUT_MAX (4u << 20)
#define CONTROL_MEASURE_DEFAULT 50
#define CONTROL_MAX_ARGS 8
#define CONTROL_WAIT_MAX (1ull << 40)	/* cycles a `wait` may span */
#define CONTROL_RX_AHEAD CONTROL_WAIT_MAX	/* cycles, as for `wait` */
#define CONTROL_WAIT_BYTES 1000000	/* bytes a `wait i2c` may wait for */

/* --- reply buffer ---------------------------------------------------------- */

typedef struct reply_t {
	char **buf;
	size_t *len, *cap;
} reply_t;

static void reply_printf(reply_t *r, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

static void reply_printf(reply_t *r, const char *fmt, ...)
{
	va_list ap;
	int n;

	for (;;) {
		size_t room = *r->cap - *r->len;

		va_start(ap, fmt);
		n = vsnprintf(*r->buf + *r->len, room, fmt, ap);
		va_end(ap);
		if (n < 0) {
			return;
		}
		if ((size_t)n < room) {
			*r->len += (size_t)n;
			return;
		}
		size_t cap = (*r->cap ? *r->cap : 256) * 2 + (size_t)n;
		char *p = realloc(*r->buf, cap);

		if (!p) {
			return;
		}
		*r->buf = p;
		*r->cap = cap;
	}
}

/* --- argument helpers ------------------------------------------------------ */

static int parse_u64(const char *s, uint64_t *out)
{
	char *end;

	if (!s || !*s || *s == '-') {
		return -1;
	}
	errno = 0;
	unsigned long long v = strtoull(s, &end, 10);

	if (errno || *end) {
		return -1;
	}
	*out = v;
	return 0;
}

static int parse_mv(const char *s, uint32_t *out)
{
	uint64_t v;

	if (parse_u64(s, &v) < 0 || v > 100000) {
		return -1;
	}
	*out = (uint32_t)v;
	return 0;
}

static int hex_digit(char ch)
{
	if (ch >= '0' && ch <= '9') {
		return ch - '0';
	}
	if (ch >= 'a' && ch <= 'f') {
		return ch - 'a' + 10;
	}
	if (ch >= 'A' && ch <= 'F') {
		return ch - 'A' + 10;
	}
	return -1;
}

/* Append the bytes of S (pairs of hex digits) to OUT[*N]. 0, or -1 when S is
 * empty, odd or not hex (*N is then unchanged). */
static int parse_hex(const char *s, uint8_t *out, size_t *n, size_t max)
{
	size_t len = strlen(s), k = *n;

	if (!len || len % 2) {
		return -1;
	}
	for (size_t i = 0; i < len; i += 2) {
		int hi = hex_digit(s[i]), lo = hex_digit(s[i + 1]);

		if (hi < 0 || lo < 0 || k == max) {
			return -1;
		}
		out[k++] = (uint8_t)(hi << 4 | lo);
	}
	*n = k;
	return 0;
}

/* --- commands -------------------------------------------------------------- */

/* The PC's rate as its port's termios say now (docs/simulator.md): read by
 * the run loop as it takes the PC's bytes, and again by the requests that
 * go by it, for a program may set its rate just before it asks (pyserial's
 * open, then `rx`): read a moment before, `rx` put its bytes on the line at
 * the old rate. */
static void pc_rate_now(control_t *c)
{
	if (c->pty) {
		usart_set_host_baud(c->usart, pty_baud(c->pty));
	}
}

/* Schedule bytes on the board's receive line: `rx CYCLE HEX...`. */
static void cmd_rx(control_t *c, reply_t *r, int argc, char **argv)
{
	uint8_t bytes[CONTROL_LINE / 2];
	size_t n = 0;
	uint64_t at, now = c->avr->cycle, free_at, room, end;
	/* `+N`: N cycles from the cycle this request is answered at, so a batch
	 * (`rx +N ...`, `wait M`, ...) keeps its spacing whatever the wall clock */
	int rel = argc >= 2 && argv[1][0] == '+';

	if (argc < 3 || (rel && argv[1][1] == '+') || parse_u64(argv[1] + rel, &at) < 0) {
		reply_printf(r, "ERR rx CYCLE HEX...: CYCLE decimal (or +N: N cycles from now), "
		   "then the bytes in hex");
		return;
	}
	if (rel) {
		if (at > CONTROL_RX_AHEAD) {
			reply_printf(r, "ERR rx: +%" PRIu64 " is more than %" PRIu64 " cycles ahead", at,
			   (uint64_t)CONTROL_RX_AHEAD);
			return;
		}
		at += now;
	}
	for (int i = 2; i < argc; i++) {
		if (parse_hex(argv[i], bytes, &n, sizeof(bytes)) < 0) {
			reply_printf(r, "ERR rx: bad hex '%s' (pairs of hex digits)", argv[i]);
			return;
		}
	}
	if (at < now) {
		reply_printf(r, "ERR rx: cycle %" PRIu64 " is past (now %" PRIu64 ")", at, now);
		return;
	}
	if (at - now > CONTROL_RX_AHEAD) {
		reply_printf(r, "ERR rx: cycle %" PRIu64 " is more than %" PRIu64 " cycles ahead", at,
		   (uint64_t)CONTROL_RX_AHEAD);
		return;
	}
	free_at = usart_inject_free_at(c->usart);
	if (at < free_at) {
		reply_printf(r, "ERR rx: the line is busy until cycle %" PRIu64, free_at);
		return;
	}
	room = usart_inject_room(c->usart);
	if (n > room) {
		reply_printf(r, "ERR rx: too many bytes: %zu, room for %" PRIu64 " (at most %u scheduled)",
		   n, room, (unsigned)USART_INJECT_QUEUE);
		return;
	}
	pc_rate_now(c);
	end = usart_inject(c->usart, at, bytes, n);
	reply_printf(r, "%" PRIu64, end);
}

static void cmd_edges(reply_t *r, signal_t *s, int have_since, uint64_t since)
{
	int any = 0;

	for (int i = (int)s->count - 1; i >= 0; i--) {
		const signal_edge_t *e = signal_edge(s, (unsigned)i);

		if (have_since && e->cycle < since) {
			continue;
		}
		reply_printf(r, "%s%" PRIu64 ":%d", any ? " " : "", e->cycle, e->level);
		any = 1;
	}
	if (!any) {
		reply_printf(r, "-");
	}
}

static void cmd_measure(control_t *c, reply_t *r, signal_t *s, unsigned nmax,
			int have_since, uint64_t since)
{
	/* edges oldest first */
	unsigned n = s->count, first = 0;
	uint64_t hmin = UINT64_MAX, hmax = 0, hsum = 0, pmin = UINT64_MAX, pmax = 0, psum = 0;
	unsigned periods = 0;
	uint64_t now = c->avr->cycle;

	/* Walk rising edges from the newest backwards: a complete period is
	 * rise -> fall -> next rise. */
	int rise_next = -1;	/* index (age) of the later rising edge */

	for (unsigned age = 0; age < n && periods < nmax; age++) {
		const signal_edge_t *e = signal_edge(s, age);

		if (have_since && e->cycle < since) {
			break;
		}
		if (!e->level) {
			continue;
		}
		if (rise_next >= 0 && (int)age == rise_next + 2) {
			const signal_edge_t *fall = signal_edge(s, age - 1);
			const signal_edge_t *next = signal_edge(s, (unsigned)rise_next);
			uint64_t high = fall->cycle - e->cycle, period = next->cycle - e->cycle;

			hmin = high < hmin ? high : hmin;
			hmax = high > hmax ? high : hmax;
			hsum += high;
			pmin = period < pmin ? period : pmin;
			pmax = period > pmax ? period : pmax;
			psum += period;
			periods++;
		}
		rise_next = (int)age;
	}
	(void)first;
	/* No complete period, or the signal stopped (no edge for more than
	 * two of its longest periods): steady. An edge may be stamped a few
	 * cycles ahead of `now`, the gateway's cycle (a slave board ends its
	 * quantum up to an instruction later; the board model places some
	 * compares itself), so a last edge after now is a recent one. */
	if (!periods || (s->count && now > s->last_cycle && now - s->last_cycle > 2 * pmax)) {
		reply_printf(r, "steady %d", s->level);
		return;
	}
	reply_printf(r, "high %" PRIu64 " %" PRIu64 " %.1f period %" PRIu64 " %" PRIu64 " %.1f duty %.4f n %u",
	   hmin, hmax, (double)hsum / periods, pmin, pmax, (double)psum / periods,
	   (double)hsum / (double)psum, periods);
}

static void cmd_spi(board_model_t *bm, reply_t *r)
{
	spi_log_t e;
	int any = 0, open = 0;
	const char *cs = NULL;
	uint32_t txn = 0;
	char mosi[2 * SPI_LOG + 1], miso[2 * SPI_LOG + 1];
	size_t nm = 0;

	while (spi_log_pop(&bm->spi, &e)) {
		if (open && (e.cs != cs || e.txn != txn)) {
			mosi[nm] = miso[nm] = 0;
			reply_printf(r, "%s%s:%s:%s", any ? " " : "", cs, mosi, miso);
			any = 1;
			open = 0;
		}
		if (!open) {
			cs = e.cs;
			txn = e.txn;
			nm = 0;
			open = 1;
		}
		if (nm + 2 < sizeof(mosi)) {
			snprintf(mosi + nm, 3, "%02X", e.mosi);
			snprintf(miso + nm, 3, "%02X", e.miso);
			nm += 2;
		}
	}
	if (open) {
		mosi[nm] = miso[nm] = 0;
		reply_printf(r, "%s%s:%s:%s", any ? " " : "", cs, mosi, miso);
		any = 1;
	}
	if (!any) {
		reply_printf(r, "-");
	}
}

/* --- requests -------------------------------------------------------------- */

/* The board with address text S ("10", hex), or NULL. */
static control_board_t *control_board_find(control_t *c, const char *s)
{
	char *end;
	unsigned long v;

	if (!*s) {
		return NULL;
	}
	v = strtoul(s, &end, 16);
	if (*end || v == 0 || v > 0xff) {
		return NULL;
	}
	for (int i = 1; i < c->nboards; i++) {
		if (c->board[i].addr == v) {
			return &c->board[i];
		}
	}
	return NULL;
}

/* NAME as "10/A5" (slave 10's A5) or "A5" (board *CB's): the name within
 * its board, *CB set to that board; NULL when no board has the prefix. */
static const char *control_name(control_t *c, const char *name, control_board_t **cb)
{
	const char *slash = strchr(name, '/');
	char prefix[8];

	if (!slash) {
		return name;
	}
	if ((size_t)(slash - name) >= sizeof(prefix)) {
		return NULL;
	}
	memcpy(prefix, name, (size_t)(slash - name));
	prefix[slash - name] = 0;
	*cb = control_board_find(c, prefix);
	return *cb ? slash + 1 : NULL;
}

static void control_list_signals(reply_t *r, const control_board_t *cb, int *any)
{
	for (int i = 0; i < cb->bm->signals.count; i++) {
		if (cb->addr) {
			reply_printf(r, "%s%02X/%s", *any ? " " : "", cb->addr,
				     cb->bm->signals.sig[i]->name);
		} else {
			reply_printf(r, "%s%s", *any ? " " : "", cb->bm->signals.sig[i]->name);
		}
		*any = 1;
	}
}

/* One request being answered. */
typedef struct control_req_ctx_t {
	control_t *c;
	control_board_t *cb;		/* the board it is about (@10, 10/A5) */
	int board_given;		/* named with @10 */
	reply_t *r;
	int argc;
	char **argv;
	control_wait_t *wait;
} control_req_ctx_t;

/* A handler: 0 (answered), 1 (the reply waits for *wait), or
 * CONTROL_WRONG (the arguments fit none of its forms). */
#define CONTROL_WRONG (-1)
typedef int (*control_req_fn)(control_req_ctx_t *q);

static int req_time(control_req_ctx_t *q)
{
	/* world time: every board counts the same cycles */
	reply_printf(q->r, "%" PRIu64, (uint64_t)q->c->avr->cycle);
	return 0;
}

/* `wait i2c N WITHIN`: until the master has clocked N more bytes (the
 * trace's `twi addr|write|read`), so a request behind it acts at a byte on
 * the bus however the firmware's timing drifts; never longer than WITHIN
 * cycles (then an error: the bytes did not come). */
static int req_wait_i2c(control_req_ctx_t *q)
{
	twi_bus_t *bus = q->c->bus;
	uint64_t n, within;

	if (q->argc != 4 || parse_u64(q->argv[2], &n) < 0 || n < 1 || n > CONTROL_WAIT_BYTES ||
	    parse_u64(q->argv[3], &within) < 0 || within < 1 || within > CONTROL_WAIT_MAX) {
		reply_printf(q->r, "ERR wait i2c N WITHIN: N bytes 1..%u, WITHIN cycles 1..%" PRIu64
			     ", decimal", (unsigned)CONTROL_WAIT_BYTES, (uint64_t)CONTROL_WAIT_MAX);
		return 0;
	}
	if (!bus) {
		reply_printf(q->r, "ERR wait i2c: no I2C bus");
		return 0;
	}
	*q->wait = (control_wait_t) { .until = q->c->avr->cycle + within,
				      .bytes = bus->bytes + (uint32_t)n, .n = (uint32_t)n };
	return 1;
}

/* `wait N`, or `wait i2c ...` (any count: its own error names the form) */
static int req_wait(control_req_ctx_t *q)
{
	uint64_t u;

	if (!strcasecmp(q->argv[1], "i2c")) {
		return req_wait_i2c(q);
	}
	if (q->argc != 2) {
		return CONTROL_WRONG;
	}
	if (parse_u64(q->argv[1], &u) < 0 || u > CONTROL_WAIT_MAX) {
		reply_printf(q->r, "ERR wait N: N cycles, decimal");
		return 0;
	}
	*q->wait = (control_wait_t) { .until = q->c->avr->cycle + u };
	return 1;
}

static int req_stack(control_req_ctx_t *q)
{
	uint64_t from = 0;
	uint32_t deepest;
	int peak;

	if (q->argc == 2 && parse_u64(q->argv[1], &from) < 0) {
		reply_printf(q->r, "ERR stack [FROM]: FROM = end of static data, decimal");
		return 0;
	}
	peak = sram_stack_peak(q->cb->avr, (uint32_t)from, &deepest);
	if (peak < 0) {
		reply_printf(q->r, "ERR FROM is not an SRAM address");
		return 0;
	}
	reply_printf(q->r, "peak %d deepest 0x%04X ramend 0x%04X", peak, (unsigned)deepest,
		     (unsigned)q->cb->avr->ramend);
	return 0;
}

static int req_isr(control_req_ctx_t *q)
{
	control_board_t *cb = q->cb;

	if (q->argc == 2 && strcasecmp(q->argv[1], "clear")) {
		return CONTROL_WRONG;
	}
	/* the board's TWI interrupt: longest run, entry to RETI */
	if (!cb->twi_isr) {
		reply_printf(q->r, "ERR isr: not watched on this board");
		return 0;
	}
	reply_printf(q->r, "twi longest %" PRIu64 " count %" PRIu64 " total %" PRIu64,
		     cb->twi_isr->longest, cb->twi_isr->count, cb->twi_isr->total);
	if (q->argc == 2) {
		isr_watch_clear(cb->twi_isr);
	}
	return 0;
}

/* `profile on|off`; `profile`: the cycles counted at each flash word,
 * as BYTEADDR:CYCLES (hex, decimal) in address order, words never run left
 * out (profile.h) */
static int req_profile(control_req_ctx_t *q)
{
	avr_t *avr = q->cb->avr;

	if (q->argc == 2) {
		if (!strcasecmp(q->argv[1], "on")) {
			if (profile_on(avr) < 0) {
				reply_printf(q->r, "ERR profile: out of memory");
			} else {
				reply_printf(q->r, "on");
			}
		} else if (!strcasecmp(q->argv[1], "off")) {
			profile_off(avr);
			reply_printf(q->r, "off");
		} else {
			return CONTROL_WRONG;
		}
		return 0;
	}
	uint32_t words;
	const uint64_t *cycles = profile_counts(avr, &words);

	if (!cycles) {
		reply_printf(q->r, "ERR profile: not on (profile on)");
		return 0;
	}
	reply_printf(q->r, "cycles");
	for (uint32_t i = 0; i < words; i++) {
		if (cycles[i]) {
			reply_printf(q->r, " %X:%" PRIu64, (unsigned)(2 * i), cycles[i]);
		}
	}
	return 0;
}

/* `flag N [clear]`: how long vector N's flag stayed raised (flag_watch_t),
 * watched from the first such request on. */
static int req_flag(control_req_ctx_t *q)
{
	control_board_t *cb = q->cb;
	flag_watch_t *w = NULL;
	uint64_t n;

	if (parse_u64(q->argv[1], &n) < 0 || n < 1 || n > 255 ||
	    (q->argc == 3 && strcasecmp(q->argv[2], "clear"))) {
		return CONTROL_WRONG;
	}
	int i = 0;
	for (; i < CONTROL_FLAG_WATCHES && cb->flags[i]; i++) {
		if (cb->flags[i]->vector == (int)n) {
			w = cb->flags[i];
			break;
		}
	}
	if (!w) {
		if (i == CONTROL_FLAG_WATCHES) {
			reply_printf(q->r, "ERR flag: %d vectors watched already", CONTROL_FLAG_WATCHES);
			return 0;
		}
		w = calloc(1, sizeof(*w));
		if (!w || flag_watch_init(w, cb->avr, (int)n) < 0) {
			free(w);
			reply_printf(q->r, "ERR flag: no vector %d on this board", (int)n);
			return 0;
		}
		cb->flags[i] = w;
	}
	reply_printf(q->r, "longest %" PRIu64 " count %" PRIu64, w->longest, w->count);
	if (q->argc == 3) {
		flag_watch_clear(w);
	}
	return 0;
}

static int req_peek(control_req_ctx_t *q)
{
	avr_t *avr = q->cb->avr;
	uint64_t addr, n = 1;

	if (parse_u64(q->argv[1], &addr) < 0 || (q->argc == 3 && parse_u64(q->argv[2], &n) < 0) ||
	    n == 0 || n > 64 || addr + n > (uint64_t)avr->ramend + 1) {
		reply_printf(q->r, "ERR peek ADDR [LEN]: data address and 1..64 bytes, decimal");
		return 0;
	}
	for (uint64_t i = 0; i < n; i++) {
		reply_printf(q->r, "%02X", avr->data[addr + i]);
	}
	return 0;
}

/* `pin P` and `drive P 0|1|z` */
static int req_pin(control_req_ctx_t *q)
{
	board_model_t *bm = q->cb->bm;
	bm_port_t *p;
	int bit;

	if (board_model_parse_pin(bm, q->argv[1], &p, &bit) < 0) {
		reply_printf(q->r, "ERR no pin '%s'", q->argv[1]);
		return 0;
	}
	if (q->argc == 3) {
		const char *v = q->argv[2];
		int level = !strcmp(v, "0") ? 0 : !strcmp(v, "1") ? 1 : !strcasecmp(v, "z") ? -1 : -2;

		if (level == -2) {
			reply_printf(q->r, "ERR drive P 0|1|z");
			return 0;
		}
		board_model_drive(bm, p, bit, level);
		reply_printf(q->r, "OK");
	} else {
		char text[32];

		board_model_pin_text(bm, p, bit, text, sizeof(text));
		reply_printf(q->r, "%s", text);
	}
	return 0;
}

static int req_adc(control_req_ctx_t *q)
{
	board_model_t *bm = q->cb->bm;
	const char *a = q->argv[1];
	uint64_t ch;
	uint32_t mv;

	/* CH, or the pin of that line of the ADC port (M32-D A5, M128-S F3) */
	if (toupper((unsigned char)a[0]) == bm->wiring->adc_port && a[1] >= '0' &&
	    a[1] <= '7' && !a[2]) {
		ch = (uint64_t)(a[1] - '0');
	} else if (parse_u64(a, &ch) < 0 || ch > 7) {
		reply_printf(q->r, "ERR adc CH [MV]: CH 0..7, or a pin of the ADC port (%c0..%c7)",
			     bm->wiring->adc_port, bm->wiring->adc_port);
		return 0;
	}
	if (q->argc == 2) {
		reply_printf(q->r, "%" PRIu32, bm->adc_mv[ch]);
	} else if (parse_mv(q->argv[2], &mv) < 0) {
		reply_printf(q->r, "ERR millivolts 0..100000");
	} else {
		board_model_set_adc(bm, (int)ch, mv);
		reply_printf(q->r, "OK");
	}
	return 0;
}

/* `avcc [MV]` and `aref [MV]` */
static int req_vref(control_req_ctx_t *q)
{
	board_model_t *bm = q->cb->bm;
	int avcc = !strcasecmp(q->argv[0], "avcc");
	uint32_t mv;

	if (q->argc == 1) {
		reply_printf(q->r, "%" PRIu32, avcc ? bm->avcc : bm->aref);
	} else if (parse_mv(q->argv[1], &mv) < 0 || mv == 0) {
		reply_printf(q->r, "ERR millivolts 1..100000");
	} else {
		if (avcc) {
			board_model_set_avcc(bm, mv);
		} else {
			board_model_set_aref(bm, mv);
		}
		reply_printf(q->r, "OK");
	}
	return 0;
}

/* `level SIG`, `edges SIG [SINCE]`, `measure SIG [N [SINCE]]` */
static int req_signal(control_req_ctx_t *q)
{
	signal_t *s = signal_find(&q->cb->bm->signals, q->argv[1]);
	uint64_t since = 0, nmax = CONTROL_MEASURE_DEFAULT;
	const char *cmd = q->argv[0];
	int argc = q->argc;

	if (!s) {
		reply_printf(q->r, "ERR no signal '%s' (see: signals)", q->argv[1]);
		return 0;
	}
	if (!strcasecmp(cmd, "level")) {
		reply_printf(q->r, "%d", s->level);
	} else if (!strcasecmp(cmd, "edges")) {
		if (argc == 3 && parse_u64(q->argv[2], &since) < 0) {
			reply_printf(q->r, "ERR edges SIG [SINCE_CYCLE]");
			return 0;
		}
		cmd_edges(q->r, s, argc == 3, since);
	} else {
		if ((argc >= 3 && (parse_u64(q->argv[2], &nmax) < 0 || nmax == 0)) ||
		    (argc == 4 && parse_u64(q->argv[3], &since) < 0)) {
			reply_printf(q->r, "ERR measure SIG [N [SINCE_CYCLE]]");
			return 0;
		}
		cmd_measure(q->c, q->r, s, nmax > SIGNAL_RING ? SIGNAL_RING : (unsigned)nmax,
			    argc == 4, since);
	}
	return 0;
}

static int req_line(control_req_ctx_t *q)
{
	usart_t *u = q->c->usart;

	pc_rate_now(q->c);
	reply_printf(q->r, "pc %u bit %u board %u ubrr %u rxen %d since %" PRIu64 " fe %u pty %u dor %u",
		     (unsigned)u->host_baud, (unsigned)u->host_bit, (unsigned)usart_board_bit(u),
		     (unsigned)u->ubrr, usart_rxen(u), (uint64_t)u->rxen_since,
		     (unsigned)u->fe_read, (unsigned)u->host_taken,
		     (unsigned)u->rx_lost);
	return 0;
}

static int req_rx(control_req_ctx_t *q)
{
	cmd_rx(q->c, q->r, q->argc, q->argv);
	return 0;
}

static int req_spi(control_req_ctx_t *q)
{
	cmd_spi(q->cb->bm, q->r);
	return 0;
}

static int req_spidev(control_req_ctx_t *q)
{
	spi_dev_t *d = board_model_spi_dev(q->cb->bm, q->argv[1]);
	char text[512];

	if (!d) {
		reply_printf(q->r, "ERR no SPI device on '%s'", q->argv[1]);
		return 0;
	}
	text[0] = 0;
	if (d->dump) {
		d->dump(d, text, sizeof(text));
	}
	reply_printf(q->r, "%s mode %d %s %s", d->kind, d->mode, d->lsb_first ? "lsb" : "msb", text);
	return 0;
}

static int req_signals(control_req_ctx_t *q)
{
	int any = 0;

	if (q->board_given) {
		control_list_signals(q->r, q->cb, &any);
	} else {
		for (int i = 0; i < q->c->nboards; i++) {
			control_list_signals(q->r, &q->c->board[i], &any);
		}
	}
	return 0;
}

static int req_fault(control_req_ctx_t *q)
{
	if (strcasecmp(q->argv[1], "hang")) {
		return CONTROL_WRONG;
	}
	/* the board stops running its program; its watchdog resets it */
	if (fault_hang(q->cb->avr) < 0) {
		reply_printf(q->r, "ERR fault hang: no free flash word for the loop");
		return 0;
	}
	reply_printf(q->r, "%" PRIu64, (uint64_t)q->c->avr->cycle);
	return 0;
}

static int req_reset(control_req_ctx_t *q)
{
	static const char *const causes[] = { "external", "power", "brownout" };
	const char *cause = NULL;

	for (unsigned i = 0; i < sizeof(causes) / sizeof(causes[0]); i++) {
		if (!strcasecmp(q->argv[1], causes[i])) {
			cause = causes[i];
		}
	}
	if (!cause || fault_reset(q->cb->avr, q->cb->bm, cause) < 0) {
		reply_printf(q->r, "ERR reset external|power|brownout");
		return 0;
	}
	reply_printf(q->r, "%" PRIu64, (uint64_t)q->c->avr->cycle);
	return 0;
}

#define I2C_ARGS "stuck N | hold-scl on|off | arb BYTE BIT | glitch start|stop BYTE BIT | disarm"

/* `i2c arb BYTE BIT`, `i2c glitch start|stop BYTE BIT`, `i2c disarm`: a
 * fault in the middle of a byte of the next transaction (twi_fault.h). */
static int req_i2c_fault(control_req_ctx_t *q, twi_bus_t *bus)
{
	char **argv = q->argv;
	twi_fault_kind_t kind = TWI_FAULT_ARB;
	uint64_t byte, bit;
	int at = 2;

	if (!strcasecmp(argv[1], "disarm") && q->argc == 2) {
		twi_fault_arm(&bus->fault, TWI_FAULT_NONE, 0, 0);
		reply_printf(q->r, "OK");
		return 0;
	}
	if (!strcasecmp(argv[1], "glitch")) {
		if (q->argc != 5 || (strcasecmp(argv[2], "start") && strcasecmp(argv[2], "stop"))) {
			reply_printf(q->r, "ERR i2c glitch start|stop BYTE BIT");
			return 0;
		}
		kind = !strcasecmp(argv[2], "start") ? TWI_FAULT_START : TWI_FAULT_STOP;
		at = 3;
	} else if (strcasecmp(argv[1], "arb") || q->argc != 4) {
		reply_printf(q->r, "ERR i2c [" I2C_ARGS "]");
		return 0;
	}
	if (parse_u64(argv[at], &byte) < 0 || parse_u64(argv[at + 1], &bit) < 0 ||
	    twi_fault_arm(&bus->fault, kind, byte > 255 ? 256 : (unsigned)byte,
			  bit > 8 ? 9 : (unsigned)bit) < 0) {
		reply_printf(q->r, kind == TWI_FAULT_ARB ?
			     "ERR i2c arb BYTE BIT: BYTE 0..255 from the next START (0: its address),"
			     " BIT 0..7 MSB first or 8 the acknowledge" :
			     "ERR i2c glitch start|stop BYTE BIT: BYTE 0..255 from the next START"
			     " (0: its address), BIT 1..8 (8: the acknowledge; bit 0 is where a"
			     " legal START or STOP goes)");
		return 0;
	}
	reply_printf(q->r, "OK");
	return 0;
}

static int req_i2c(control_req_ctx_t *q)
{
	twi_bus_t *bus = q->c->bus;
	char **argv = q->argv;
	uint64_t u, now = q->c->avr->cycle;

	if (!bus) {
		return CONTROL_WRONG;
	}
	if (q->argc == 3 && !strcasecmp(argv[1], "stuck")) {
		if (parse_u64(argv[2], &u) < 0 || u > 1000000) {
			reply_printf(q->r, "ERR i2c stuck N: N SCL pulses, 0..1000000 (0: SDA free)");
			return 0;
		}
		twi_bus_stuck(bus, (uint32_t)u, now);
		reply_printf(q->r, "OK");
	} else if (q->argc == 3 && !strcasecmp(argv[1], "hold-scl") &&
		   (!strcasecmp(argv[2], "on") || !strcasecmp(argv[2], "off"))) {
		twi_bus_hold_scl(bus, !strcasecmp(argv[2], "on"), now);
		reply_printf(q->r, "OK");
	} else if (q->argc >= 2 && (!strcasecmp(argv[1], "arb") || !strcasecmp(argv[1], "glitch") ||
				    !strcasecmp(argv[1], "disarm"))) {
		return req_i2c_fault(q, bus);
	} else if (q->argc == 1) {
		char fault[40];

		reply_printf(q->r, "sda %d scl %d stuck %" PRIu32 " hold-scl %s fault %s", bus->sda,
			     bus->scl, bus->stuck, bus->hold_scl ? "on" : "off",
			     twi_fault_describe(&bus->fault, fault, sizeof(fault)));
	} else {
		reply_printf(q->r, "ERR i2c [" I2C_ARGS "]");
	}
	return 0;
}

/* `sense @ADDR QUANTITY V...`: what the part at bus address ADDR (8-bit,
 * hex: @D0, @0xD0) senses, in physical units (part.h). */
static int req_sense(control_req_ctx_t *q)
{
	char **argv = q->argv;
	const char *a = argv[1];
	uint64_t addr;
	double v[8];
	char err[160], senses_buf[80], *end;
	const char *senses;
	int n = q->argc - 3;
	const part_t *p;

	if (*a == '@') {
		a++;
	}
	if (!strncasecmp(a, "0x", 2)) {
		a += 2;
	}
	addr = strtoull(a, &end, 16);
	if (!*a || *end || addr > 0xFF) {
		reply_printf(q->r, "ERR sense @ADDR QUANTITY V...: ADDR the part's 8-bit bus"
			     " address in hex (@D0), not '%s'", argv[1]);
		return 0;
	}
	p = q->c->parts ? part_list_at(q->c->parts, (uint8_t)(addr & 0xFE)) : NULL;
	if (!p) {
		reply_printf(q->r, "ERR sense: no part at %02X", (unsigned)addr);
		return 0;
	}
	senses = part_kind_senses(p->kind, senses_buf, sizeof(senses_buf));
	if (!senses) {
		reply_printf(q->r, "ERR sense: the %s at %02X senses nothing", p->kind->name,
			     (unsigned)p->addr8);
		return 0;
	}
	if (n > (int)(sizeof(v) / sizeof(v[0]))) {
		reply_printf(q->r, "ERR sense: too many values");
		return 0;
	}
	for (int i = 0; i < n; i++) {
		v[i] = strtod(argv[3 + i], &end);
		if (end == argv[3 + i] || *end || !isfinite(v[i])) {
			reply_printf(q->r, "ERR sense: '%s' is not a number", argv[3 + i]);
			return 0;
		}
	}
	if (!part_sense_units(argv[2])) {
		reply_printf(q->r, "ERR sense: no quantity '%s' (the %s at %02X senses: %s)",
			     argv[2], p->kind->name, (unsigned)p->addr8, senses);
		return 0;
	}
	err[0] = 0;
	if (part_sense(p->kind, p->self, q->c->avr->cycle, argv[2], v, n, err, sizeof(err)) < 0) {
		reply_printf(q->r, "ERR sense: %s", err[0] ? err : "refused");
		return 0;
	}
	reply_printf(q->r, "OK");
	return 0;
}

static int req_help(control_req_ctx_t *q);

/* Which boards a request reaches. */
enum {
	CONTROL_ANY_BOARD,		/* the gateway, or a slave by @10 or 10/NAME */
	CONTROL_NAMES_BOARD,		/* ... and its first argument may be 10/NAME */
	CONTROL_GATEWAY,		/* the gateway's serial line only */
	CONTROL_PART,			/* @ADDR names a part on the I2C bus, not a board */
};

/* The requests: name, arguments (the help line; a request of two forms
 * names the second after a " | ", as the help separates requests), the
 * argument counts it takes (the name included), which boards, the handler. */
typedef struct control_req_t {
	const char *name;
	const char *args;
	int min_argc, max_argc;
	int boards;
	control_req_fn fn;
} control_req_t;

static const control_req_t control_reqs[] = {
	{ "time", "", 1, 1, CONTROL_ANY_BOARD, req_time },
	{ "wait", "N | wait i2c N WITHIN", 2, 4, CONTROL_ANY_BOARD, req_wait },
	{ "pin", "P", 2, 2, CONTROL_NAMES_BOARD, req_pin },
	{ "drive", "P 0|1|z", 3, 3, CONTROL_NAMES_BOARD, req_pin },
	{ "adc", "CH [MV]", 2, 3, CONTROL_NAMES_BOARD, req_adc },
	{ "avcc", "[MV]", 1, 2, CONTROL_ANY_BOARD, req_vref },
	{ "aref", "[MV]", 1, 2, CONTROL_ANY_BOARD, req_vref },
	{ "level", "SIG", 2, 2, CONTROL_NAMES_BOARD, req_signal },
	{ "edges", "SIG [SINCE]", 2, 3, CONTROL_NAMES_BOARD, req_signal },
	{ "measure", "SIG [N [SINCE]]", 2, 4, CONTROL_NAMES_BOARD, req_signal },
	{ "spi", "", 1, 1, CONTROL_ANY_BOARD, req_spi },
	{ "spidev", "P", 2, 2, CONTROL_NAMES_BOARD, req_spidev },
	{ "stack", "[FROM]", 1, 2, CONTROL_ANY_BOARD, req_stack },
	{ "isr", "[clear]", 1, 2, CONTROL_ANY_BOARD, req_isr },
	{ "flag", "VECTOR [clear]", 2, 3, CONTROL_ANY_BOARD, req_flag },
	{ "peek", "ADDR [LEN]", 2, 3, CONTROL_ANY_BOARD, req_peek },
	{ "profile", "[on|off]", 1, 2, CONTROL_ANY_BOARD, req_profile },
	{ "rx", "CYCLE HEX...", 0, CONTROL_MAX_ARGS, CONTROL_GATEWAY, req_rx },
	{ "line", "", 1, 1, CONTROL_GATEWAY, req_line },
	{ "signals", "", 1, 1, CONTROL_ANY_BOARD, req_signals },
	{ "i2c", "[" I2C_ARGS "]", 0, 5, CONTROL_ANY_BOARD, req_i2c },
	{ "fault", "hang", 2, 2, CONTROL_ANY_BOARD, req_fault },
	{ "reset", "external|power|brownout", 2, 2, CONTROL_ANY_BOARD, req_reset },
	{ "sense", "@ADDR QUANTITY V...", 3, CONTROL_MAX_ARGS, CONTROL_PART, req_sense },
	{ "help", "", 1, 1, CONTROL_ANY_BOARD, req_help },
};

#define CONTROL_NREQS ((int)(sizeof(control_reqs) / sizeof(control_reqs[0])))

static void control_help(reply_t *r)
{
	int any = 0;

	for (int i = 0; i < CONTROL_NREQS; i++) {
		const control_req_t *e = &control_reqs[i];

		reply_printf(r, "%s%s%s%s", any ? " | " : "", e->name, *e->args ? " " : "", e->args);
		any = 1;
	}
	for (int k = 0; part_kinds[k]; k++) {
		for (int i = 0; i < part_kinds[k]->nrequests; i++) {
			const part_request_t *e = &part_kinds[k]->requests[i];

			reply_printf(r, " | %s %s", e->name, e->args);
		}
	}
	reply_printf(r, "; a slave board's pins, signals and inputs as 10/A5, other requests"
		     " with @10 first (stack @10 FROM)");
}

static int req_help(control_req_ctx_t *q)
{
	control_help(q->r);
	return 0;
}

/* A request a part kind adds (part.h), or NULL. */
static const part_request_t *control_part_request(const char *name)
{
	for (int k = 0; part_kinds[k]; k++) {
		for (int i = 0; i < part_kinds[k]->nrequests; i++) {
			if (!strcasecmp(part_kinds[k]->requests[i].name, name)) {
				return &part_kinds[k]->requests[i];
			}
		}
	}
	return NULL;
}

int control_request(control_t *c, const char *line, char **out, size_t *len,
		    size_t *cap, control_wait_t *wait)
{
	reply_t r = { out, len, cap };
	char buf[CONTROL_LINE];
	char *argv[CONTROL_MAX_ARGS + 1], *save = NULL, *tok;
	int argc = 0;
	control_req_ctx_t q = { .c = c, .cb = &c->board[0], .r = &r, .wait = wait };
	const control_req_t *e = NULL;
	const part_request_t *pr;
	int rc;

	snprintf(buf, sizeof(buf), "%s", line);
	for (tok = strtok_r(buf, " \t\r", &save); tok && argc <= CONTROL_MAX_ARGS;
	     tok = strtok_r(NULL, " \t\r", &save)) {
		argv[argc++] = tok;
	}
	c->activity++;
	if (argc == 0) {
		reply_printf(&r, "ERR empty request");
		return 0;
	}
	if (argc > CONTROL_MAX_ARGS) {
		reply_printf(&r, "ERR too many arguments");
		return 0;
	}
	for (int i = 0; i < CONTROL_NREQS && !e; i++) {
		if (!strcasecmp(argv[0], control_reqs[i].name)) {
			e = &control_reqs[i];
		}
	}
	/* `@10` as the first argument: the request is about slave board 10
	 * (a part's request takes it as the part's bus address) */
	if (argc >= 2 && argv[1][0] == '@' && !(e && e->boards == CONTROL_PART)) {
		q.cb = control_board_find(c, argv[1] + 1);
		if (!q.cb) {
			reply_printf(&r, "ERR no board '%s' (slave boards: @ and the address, like @10)",
				     argv[1]);
			return 0;
		}
		q.board_given = 1;
		memmove(&argv[1], &argv[2], (size_t)(argc - 2) * sizeof(argv[0]));
		argc--;
	}
	/* A request naming a pin, signal or input may name a slave's: 10/A5. */
	if (e && e->boards == CONTROL_NAMES_BOARD && argc >= 2 && strchr(argv[1], '/')) {
		const char *name = control_name(c, argv[1], &q.cb);

		if (!name) {
			reply_printf(&r, "ERR no board for '%s' (slave names: the address, a slash,"
				     " the name: 10/A5)", argv[1]);
			return 0;
		}
		argv[1] = (char *)name;
	}
	q.argc = argc;
	q.argv = argv;
	if (e && argc >= e->min_argc && argc <= e->max_argc) {
		if (e->boards == CONTROL_GATEWAY && q.cb != &c->board[0]) {
			reply_printf(&r, "ERR %s: only the gateway's serial line reaches the PC",
				     e->name);
			return 0;
		}
		rc = e->fn(&q);
		if (rc != CONTROL_WRONG) {
			return rc;
		}
	} else if (!e && (pr = control_part_request(argv[0]))) {
		char text[256];

		pr->fn(c->parts, c->avr->cycle, argc, argv, text, sizeof(text));
		reply_printf(&r, "%s", text);
		return 0;
	}
	reply_printf(&r, "ERR unknown request or wrong arguments: ");
	control_help(&r);
	return 0;
}

/* --- socket ---------------------------------------------------------------- */

int control_open(control_t *c, const char *path, avr_t *avr, board_model_t *bm,
		 usart_t *usart, twi_bus_t *bus, const part_list_t *parts)
{
	struct sockaddr_un sa = { .sun_family = AF_UNIX };

	memset(c, 0, sizeof(*c));
	c->fd = -1;
	c->avr = avr;
	c->usart = usart;
	c->bus = bus;
	c->parts = parts;
	c->board[0] = (control_board_t) { .addr = 0, .avr = avr, .bm = bm };
	c->nboards = 1;
	for (int i = 0; i < CONTROL_CLIENTS; i++) {
		c->client[i].fd = -1;
	}
	if (strlen(path) >= sizeof(sa.sun_path)) {
		errno = ENAMETOOLONG;
		return -1;
	}
	strcpy(sa.sun_path, path);
	unlink(path);
	c->fd = socket(AF_UNIX, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
	if (c->fd < 0) {
		return -1;
	}
	if (bind(c->fd, (struct sockaddr *)&sa, sizeof(sa)) < 0 || listen(c->fd, 8) < 0) {
		int e = errno;

		close(c->fd);
		c->fd = -1;
		errno = e;
		return -1;
	}
	c->path = strdup(path);
	return 0;
}

int control_add_board(control_t *c, uint8_t addr, avr_t *avr, board_model_t *bm)
{
	if (c->fd < 0 || c->nboards == CONTROL_MAX_BOARDS) {
		return -1;
	}
	c->board[c->nboards++] = (control_board_t) { .addr = addr, .avr = avr, .bm = bm };
	return 0;
}

static void client_drop(control_client_t *cl)
{
	close(cl->fd);
	cl->fd = -1;
	free(cl->out);
	cl->out = NULL;
	cl->out_len = cl->out_cap = 0;
	cl->in_len = 0;
	cl->waiting = 0;
	cl->overlong = 0;
}

static void client_reply_end(control_client_t *cl)
{
	reply_t r = { &cl->out, &cl->out_len, &cl->out_cap };

	reply_printf(&r, "\n");
}

/* Answer the complete lines in CL's input until one must wait. */
static void client_process(control_t *c, control_client_t *cl)
{
	while (!cl->waiting && cl->fd >= 0) {
		char *nl = memchr(cl->in, '\n', cl->in_len);

		if (!nl) {
			if (cl->in_len == sizeof(cl->in)) {
				cl->overlong = 1;	/* drop until the newline */
				cl->in_len = 0;
			}
			return;
		}
		*nl = 0;
		size_t used = (size_t)(nl - cl->in) + 1;

		if (cl->overlong) {
			reply_t r = { &cl->out, &cl->out_len, &cl->out_cap };

			reply_printf(&r, "ERR line too long");
			client_reply_end(cl);
			cl->overlong = 0;
		} else if (control_request(c, cl->in, &cl->out, &cl->out_len, &cl->out_cap,
					   &cl->wait)) {
			cl->waiting = 1;
		} else {
			client_reply_end(cl);
		}
		memmove(cl->in, cl->in + used, cl->in_len - used);
		cl->in_len -= used;
	}
}

/* The bytes CL's `wait i2c` still waits for: 0 once they came, or for a
 * wait for a cycle. The count wraps at 2^32; a wait spans far fewer. */
static uint32_t client_bytes_due(const control_t *c, const control_client_t *cl)
{
	int32_t due;

	if (!cl->wait.n) {
		return 0;
	}
	due = (int32_t)(cl->wait.bytes - c->bus->bytes);
	return due > 0 ? (uint32_t)due : 0;
}

/* Answer CL's wait if it is over: the cycle it ended at, or the error of a
 * `wait i2c` whose bound passed before its bytes came. */
static void client_wait_over(control_t *c, control_client_t *cl)
{
	reply_t r = { &cl->out, &cl->out_len, &cl->out_cap };
	uint32_t due = client_bytes_due(c, cl);
	uint64_t now = c->avr->cycle;

	/* a `wait i2c` whose bytes came is answered even at its bound: they
	 * came in the quantum that reached it (world_run stops at the end of
	 * the quantum they came in) */
	if ((!cl->wait.n || due) && now < cl->wait.until) {
		return;
	}
	cl->waiting = 0;
	if (due) {
		reply_printf(&r, "ERR wait i2c: %" PRIu32 " of %" PRIu32 " bytes by cycle %" PRIu64
			     "\n", cl->wait.n - due, cl->wait.n, cl->wait.until);
		return;
	}
	reply_printf(&r, "%" PRIu64 "\n", now);
}

void control_poll(control_t *c)
{
	if (c->fd < 0) {
		return;
	}
	for (;;) {
		int fd = accept4(c->fd, NULL, NULL, SOCK_NONBLOCK | SOCK_CLOEXEC);
		int slot = -1;

		if (fd < 0) {
			break;
		}
		for (int i = 0; i < CONTROL_CLIENTS; i++) {
			if (c->client[i].fd < 0) {
				slot = i;
				break;
			}
		}
		if (slot < 0) {
			static const char busy[] = "ERR too many clients\n";

			if (write(fd, busy, sizeof(busy) - 1) < 0) {
				/* nothing to do */
			}
			close(fd);
			continue;
		}
		c->client[slot].fd = fd;
		c->activity++;
	}
	for (int i = 0; i < CONTROL_CLIENTS; i++) {
		control_client_t *cl = &c->client[i];

		if (cl->fd < 0) {
			continue;
		}
		if (cl->waiting) {
			client_wait_over(c, cl);
		}
		if (cl->in_len < sizeof(cl->in)) {
			ssize_t n = read(cl->fd, cl->in + cl->in_len, sizeof(cl->in) - cl->in_len);

			if (n == 0 || (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK &&
				       errno != EINTR)) {
				client_drop(cl);
				continue;
			}
			if (n > 0) {
				cl->in_len += (size_t)n;
			}
		}
		client_process(c, cl);
		if (cl->out_len) {
			ssize_t n = write(cl->fd, cl->out, cl->out_len);

			if (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) {
				client_drop(cl);
				continue;
			}
			if (n > 0) {
				memmove(cl->out, cl->out + n, cl->out_len - (size_t)n);
				cl->out_len -= (size_t)n;
			}
			if (cl->out_len > CONTROL_OUT_MAX) {
				client_drop(cl);	/* a client that never reads */
			}
		}
	}
}

int control_waiting(const control_t *c)
{
	for (int i = 0; i < CONTROL_CLIENTS; i++) {
		if (c->client[i].fd >= 0 && c->client[i].waiting) {
			return 1;
		}
	}
	return 0;
}

uint64_t control_deadline(const control_t *c)
{
	uint64_t d = UINT64_MAX;

	for (int i = 0; i < CONTROL_CLIENTS; i++) {
		const control_client_t *cl = &c->client[i];

		if (cl->fd >= 0 && cl->waiting && cl->wait.until < d) {
			d = cl->wait.until;
		}
	}
	return d;
}

uint32_t control_bytes_due(const control_t *c)
{
	uint32_t fewest = 0;

	for (int i = 0; i < CONTROL_CLIENTS; i++) {
		const control_client_t *cl = &c->client[i];
		uint32_t due = cl->fd >= 0 && cl->waiting ? client_bytes_due(c, cl) : 0;

		if (due && (!fewest || due < fewest)) {
			fewest = due;
		}
	}
	return fewest;
}

int control_pollfds(const control_t *c, struct pollfd *pfd, int max)
{
	int n = 0;

	if (c->fd < 0) {
		return 0;
	}
	if (n < max) {
		pfd[n++] = (struct pollfd) { .fd = c->fd, .events = POLLIN };
	}
	for (int i = 0; i < CONTROL_CLIENTS && n < max; i++) {
		if (c->client[i].fd >= 0) {
			pfd[n++] = (struct pollfd) { .fd = c->client[i].fd, .events = POLLIN };
		}
	}
	return n;
}

void control_close(control_t *c)
{
	for (int i = 0; i < CONTROL_CLIENTS; i++) {
		if (c->client[i].fd >= 0) {
			client_drop(&c->client[i]);
		}
	}
	if (c->fd >= 0) {
		close(c->fd);
		c->fd = -1;
	}
	if (c->path) {
		unlink(c->path);
		free(c->path);
		c->path = NULL;
	}
}
