/*
 * The serial gateway under fuzz: bytes into sg_parse_char() as the UART
 * delivers them, requests into sg_exec(), every reply checked against what
 * docs/protocol.md promises:
 *  - replies come only when a line ends (or for lost characters), as whole
 *    lines of at most 127 characters + CR LF;
 *  - each reply has the form its request asks for (V1.1, X, Lxx, Cxxxx,
 *    SW/SR...P matching the request's frames, or ERROR 02..07; never 01);
 *  - nothing of a request with a parse error, or of one that lost
 *    characters, is executed;
 *  - without lost-run markers in the input: every line with content that is
 *    not a comment gets exactly one reply, empty lines and comments none;
 *    a request of more than 128 characters is an error; and a request that
 *    is accepted is exactly what its line says (printed back from the
 *    parsed frames, it equals the line without spaces, in upper case);
 *  - through the receive ring (serialgate/sg_rx.c), overflowing: every
 *    request line of the stream put in gets one reply, lost or not.
 */
#include <ctype.h>
#include <stdio.h>
#include <string.h>

#include "fakes.h"
#include "fuzz.h"
#include "serialgate/sg_exec.h"
#include "serialgate/sg_parse.h"
#include "serialgate/sg_rx.h"

#define LINE_KEEP 512

static sg_parser_t parser;

static struct {
	uint8_t local;      /* the local address the replies have shown */
	uint16_t khz;       /* the clock C answers, once seen (0: not yet) */
	int clean;          /* no lost-run markers in the input */
	char line[LINE_KEEP];
	unsigned len;       /* characters of the line so far (may exceed LINE_KEEP) */
	int content, comment, first;
} g;

static int hex_digit(char c)
{
	return (c >= '0' && c <= '9') || (c >= 'A' && c <= 'F');
}

static unsigned hex_at(const char *s, unsigned digits)
{
	unsigned v = 0;
	for (unsigned i = 0; i < digits; i++) {
		v = v << 4 | (unsigned)(s[i] <= '9' ? s[i] - '0' : s[i] - 'A' + 10);
	}
	return v;
}

static int all_hex(const char *s, size_t n)
{
	for (size_t i = 0; i < n; i++) {
		if (!hex_digit(s[i])) {
			return 0;
		}
	}
	return 1;
}

/* The parser's request, before it runs: well-formed within the limits. */
static void check_parsed(const sg_parser_t *p)
{
	FUZZ_REQUIRE(p->err != SG_ERR_INTERNAL, "the parser reported an internal error");
	if (p->err != SG_OK) {
		FUZZ_REQUIRE(p->err >= SG_ERR_COMMAND && p->err <= SG_ERR_NO_P,
			     "parse error %02X is not a parser's code", p->err);
		return;
	}
	FUZZ_REQUIRE(p->nbytes <= SG_BUF_SIZE, "request of %u bytes", p->nbytes);
	switch (p->cmd) {
	case SG_CMD_VERSION:
	case SG_CMD_CLEAR:
		FUZZ_REQUIRE(p->nbytes == 0, "V/X with %u bytes", p->nbytes);
		break;
	case SG_CMD_LOCAL:
		FUZZ_REQUIRE(p->nbytes == 0 || (p->nbytes == 1 && (p->buf[0] & 0xFE) != 0),
			     "L with %u bytes (%02X)", p->nbytes, p->buf[0]);
		break;
	case SG_CMD_CLOCK:
		FUZZ_REQUIRE(p->nbytes == 0 || (p->nbytes == 2 && (p->buf[0] | p->buf[1]) != 0),
			     "C with %u bytes", p->nbytes);
		break;
	case SG_CMD_I2C: {
		unsigned i = 0, reply = 1, frames = 0;
		while (i < p->nbytes) {
			FUZZ_REQUIRE(i + 2 <= p->nbytes, "frame header past the request");
			uint8_t addr = p->buf[i], n = p->buf[i + 1];
			FUZZ_REQUIRE(!(addr & 1) || n >= 1, "read frame of 0 bytes");
			reply += 2 + ((addr & 1) ? 2u * n : n);
			i += 2u + n;
			frames++;
		}
		FUZZ_REQUIRE(i == p->nbytes && frames >= 1, "frames do not add up to the request");
		FUZZ_REQUIRE(reply <= SG_REPLY_MAX, "accepted a request whose reply is %u long", reply);
		break;
	}
	default:
		FUZZ_REQUIRE(0, "request without a command (%u)", p->cmd);
	}
}

/* The request printed back as a line without spaces (before it runs). */
static size_t render(const sg_parser_t *p, char *dst)
{
	size_t k = 0;
	switch (p->cmd) {
	case SG_CMD_VERSION:
		return (size_t)sprintf(dst, "V");
	case SG_CMD_CLEAR:
		return (size_t)sprintf(dst, "X");
	case SG_CMD_LOCAL:
	case SG_CMD_CLOCK:
		k = (size_t)sprintf(dst, p->cmd == SG_CMD_LOCAL ? "L" : "C");
		for (unsigned i = 0; i < p->nbytes; i++) {
			k += (size_t)sprintf(dst + k, "%02X", p->buf[i]);
		}
		return k;
	default:
		break;
	}
	for (unsigned i = 0; i < p->nbytes;) {
		uint8_t addr = p->buf[i], n = p->buf[i + 1];
		k += (size_t)sprintf(dst + k, "S%02X", addr);
		if (addr & 1) {
			k += (size_t)sprintf(dst + k, "%02X", n);
		} else {
			for (unsigned j = 0; j < n; j++) {
				k += (size_t)sprintf(dst + k, "%02X", p->buf[i + 2 + j]);
			}
		}
		i += 2u + n;
	}
	dst[k++] = 'P';
	dst[k] = 0;
	return k;
}

/* One reply line (without CR LF) to the request the parser completed. */
static void check_reply(const sg_parser_t *p, const char *r, size_t n)
{
	char want[300];
	FUZZ_REQUIRE(n <= SG_REPLY_MAX, "reply of %zu characters", n);
	if (p->err != SG_OK) {
		snprintf(want, sizeof want, "ERROR %02X", p->err);
		FUZZ_REQUIRE(n == 8 && memcmp(r, want, 8) == 0, "a parse error %02X answered %.*s",
			     p->err, (int)n, r);
		return;
	}
	switch (p->cmd) {
	case SG_CMD_VERSION:
		FUZZ_REQUIRE(n == 4 && memcmp(r, "V1.1", 4) == 0, "V answered %.*s", (int)n, r);
		return;
	case SG_CMD_CLEAR:
		FUZZ_REQUIRE(n == 1 && r[0] == 'X', "X answered %.*s", (int)n, r);
		return;
	case SG_CMD_LOCAL:
		FUZZ_REQUIRE(n == 3 && r[0] == 'L' && all_hex(r + 1, 2), "L answered %.*s", (int)n, r);
		if (p->nbytes) {
			g.local = p->buf[0] & 0xFE;
		}
		FUZZ_REQUIRE(hex_at(r + 1, 2) == g.local, "L answered %.*s, local address is %02X",
			     (int)n, r, g.local);
		return;
	case SG_CMD_CLOCK: {
		FUZZ_REQUIRE(n == 5 && r[0] == 'C' && all_hex(r + 1, 4), "C answered %.*s", (int)n, r);
		unsigned khz = hex_at(r + 1, 4);
		FUZZ_REQUIRE(khz <= 460, "clock %u kHz is more than the TWI makes", khz);
		if (p->nbytes) {
			unsigned asked = (unsigned)(p->buf[0] << 8 | p->buf[1]);
			FUZZ_REQUIRE(khz <= asked, "clock %u kHz set for %u asked", khz, asked);
		} else if (g.khz) {
			FUZZ_REQUIRE(khz == g.khz, "C answered %u kHz, was %u", khz, g.khz);
		}
		g.khz = (uint16_t)khz;
		return;
	}
	default:
		break;
	}
	/* I2C: only the execution errors, or every frame as requested */
	if (n >= 6 && memcmp(r, "ERROR ", 6) == 0) {
		FUZZ_REQUIRE(n == 8 && (memcmp(r + 6, "06", 2) == 0 || memcmp(r + 6, "07", 2) == 0),
			     "I2C request answered %.*s", (int)n, r);
		return;
	}
	size_t k = 0;
	for (unsigned i = 0; i < p->nbytes;) {
		uint8_t addr = p->buf[i], m = p->buf[i + 1];
		const uint8_t *data = &p->buf[i + 2];
		k += (size_t)sprintf(want + k, (addr & 1) ? "SR" : "SW");
		for (unsigned j = 0; j < m; j++) {
			k += (addr & 1) ? (size_t)sprintf(want + k, "%02X", data[j])
					: (size_t)sprintf(want + k, "A");
		}
		i += 2u + m;
	}
	want[k++] = 'P';
	want[k] = 0;
	FUZZ_REQUIRE(n == k && memcmp(r, want, k) == 0, "I2C request answered %.*s, want %s",
		     (int)n, r, want);
}

/* The output since `from`: whole reply lines; returns how many. */
static unsigned reply_lines(unsigned from, const sg_parser_t *p, int is_request)
{
	unsigned lines = 0, start = from;
	for (unsigned i = from; i < out_len; i++) {
		char c = out_buf[i];
		if (c != '\n') {
			FUZZ_REQUIRE(c == '\r' ? i + 1 < out_len && out_buf[i + 1] == '\n'
				     : c >= ' ' && c < 0x7F, "reply byte %02X", (uint8_t)c);
			continue;
		}
		FUZZ_REQUIRE(i > start && out_buf[i - 1] == '\r', "LF without CR");
		const char *r = &out_buf[start];
		size_t n = i - 1 - start;
		if (is_request) {
			check_reply(p, r, n);
		} else {
			/* lost characters */
			FUZZ_REQUIRE(n == 8 && memcmp(r, "ERROR 04", 8) == 0,
				     "lost characters answered %.*s", (int)n, r);
		}
		lines++;
		start = i + 1;
	}
	FUZZ_REQUIRE(start == out_len, "a reply does not end with CR LF");
	return lines;
}

static void line_char(uint8_t c)
{
	if (g.len < LINE_KEEP) {
		g.line[g.len] = (char)c;
	}
	g.len++;
	if (g.first && c == '#') {
		g.comment = 1;
	} else if (c != ' ') {
		g.content = 1;
	}
	g.first = 0;
}

static void line_end(sg_event_t ev, unsigned replies, int accepted, const char *rendered)
{
	unsigned want = g.content && !g.comment;
	FUZZ_REQUIRE(replies == want, "a line (%u characters, %s) got %u replies", g.len,
		     !g.content ? "empty" : g.comment ? "a comment" : "a request", replies);
	FUZZ_REQUIRE(want == (ev == SG_REQUEST), "parser event %d for a line that %s", ev,
		     want ? "wants a reply" : "wants none");
	if (want && g.len > SG_LINE_MAX) {
		FUZZ_REQUIRE(!accepted, "a request of %u characters accepted", g.len);
	}
	if (accepted && g.len <= LINE_KEEP) {
		char norm[LINE_KEEP + 1];
		size_t k = 0;
		for (unsigned i = 0; i < g.len; i++) {
			if (g.line[i] != ' ') {
				norm[k++] = (char)toupper((unsigned char)g.line[i]);
			}
		}
		norm[k] = 0;
		FUZZ_REQUIRE(strcmp(norm, rendered) == 0, "line \"%s\" accepted as \"%s\"", norm,
			     rendered);
	}
	g.len = 0;
	g.content = g.comment = 0;
	g.first = 1;
}

/* One character into the parser, the request or lost run it ends executed
 * and its replies checked; returns the replies. */
static unsigned feed(uint8_t c, sg_event_t *evp, int *acceptedp, char *rendered)
{
	int accepted = 0;
	unsigned replies = 0;

	out_len = 0;
	bus_log[0] = 0;
	rendered[0] = 0;
	sg_event_t ev = sg_parse_char(&parser, c);
	if (ev == SG_REQUEST) {
		check_parsed(&parser);
		accepted = parser.err == SG_OK;
		if (accepted) {
			render(&parser, rendered);
		} else {
			fuzz_gate_save();
		}
		sg_exec(&parser);
		replies = reply_lines(0, &parser, 1);
		FUZZ_REQUIRE(replies == 1, "a request got %u replies", replies);
		if (!accepted) {
			FUZZ_REQUIRE(fuzz_gate_unchanged() && bus_log[0] == 0,
				     "a request with a parse error changed something (bus: %s)",
				     bus_log);
		}
		accepted = accepted && out_buf[0] != 'E';
		if (accepted && parser.cmd == SG_CMD_I2C) {
			/* frames to the local address never reach the bus */
			int on_bus = 0;
			for (unsigned k = 0; k < parser.nbytes; k += 2u + parser.buf[k + 1]) {
				on_bus |= (parser.buf[k] & 0xFE) != g.local;
			}
			FUZZ_REQUIRE(on_bus || bus_log[0] == 0,
				     "a local request went on the bus: %s", bus_log);
		}
		fuzz_gate_after_line();
	} else if (ev == SG_LOST) {
		/* a made-up record may claim thousands: the form of a few
		 * hundred replies is as telling, and keeps each input quick */
		if (parser.lost > 300) {
			parser.lost = 300;
		}
		unsigned want = parser.lost;
		fuzz_gate_save();
		sg_exec_lost(&parser);
		replies = reply_lines(0, &parser, 0);
		FUZZ_REQUIRE(replies == want, "%u lost requests, %u replies", want, replies);
		FUZZ_REQUIRE(fuzz_gate_unchanged() && bus_log[0] == 0,
			     "lost characters changed something");
	} else {
		FUZZ_REQUIRE(out_len == 0, "a reply before the line ended");
	}
	*evp = ev;
	*acceptedp = accepted;
	return replies;
}

/* The whole receive path: characters into the ring (serialgate/sg_rx.c) as
 * the UART interrupt puts them, taken out at a rate the first byte sets, so
 * the ring overflows now and then (input bytes F8..FF: bursts). Whatever was lost, every line of the
 * original stream that is a request gets exactly one reply, in all. */
static void run_ring(const uint8_t *data, size_t size)
{
	uint32_t rng = (uint32_t)data[0] * 2654435761u | 1;
	unsigned rate = data[0] >> 2;   /* in 64ths of a character per character */
	unsigned want = 0, got = 0;
	char rendered[300];
	sg_event_t ev;
	int accepted;

	uint8_t c = ' ';
	sg_rx_init();
	for (size_t i = 1; i <= size; i++) {
		/* bytes F8..FF: a burst, the character before 32..256 times
		 * more with nothing taken out (overflows from short inputs) */
		unsigned times = 1;
		if (i < size && data[i] >= 0xF8) {
			times = 32u * (data[i] - 0xF7u);
		} else if (i < size) {
			c = data[i];
		}
		for (; i < size && times; times--) {
			sg_rx_put(c);
			if (c == '\r' || c == '\n') {
				want += g.content && !g.comment;
				g.content = g.comment = 0;
				g.first = 1;
			} else {
				line_char(c >= 0x80 ? 0x7F : c);
				g.len = 0;
			}
		}
		rng = rng * 1103515245u + 12345u;
		unsigned k = ((rng >> 8) & 63) < rate ? 1 : 0;
		if (((rng >> 20) & 15) == 0) {
			k += 3;
		}
		if (i == size) {
			k = 100000;   /* the host went quiet: everything is taken */
		}
		for (; k; k--) {
			int16_t c = sg_rx_get();
			if (c < 0 && i == size && sg_rx_losing()) {
				sg_rx_close();
				c = sg_rx_get();
			}
			if (c < 0) {
				break;
			}
			got += feed((uint8_t)c, &ev, &accepted, rendered);
			if (ev == SG_MORE && sg_rx.tail != sg_rx.head) {
				/* as front_poll() does: the rest of the run at once */
				sg_rx.tail = sg_parse_run(&parser, sg_rx.buf, sg_rx.tail, &sg_rx.head);
			}
		}
	}
	FUZZ_REQUIRE(got == want, "%u requests, %u replies (through the receive ring)", want, got);
}

void fuzz_gate_run(const uint8_t *data, size_t size)
{
	if (size == 0) {
		return;
	}
	fakes_reset();
	fuzz_gate_boot();
	sg_parse_init(&parser);
	sg_exec_init();
	memset(&g, 0, sizeof g);
	g.local = SG_LOCAL_DEFAULT;
	g.first = 1;
	g.clean = data[0] % 3 == 0;
	if (data[0] % 3 == 2) {
		run_ring(data, size);
		return;
	}

	for (size_t i = 1; i < size; i++) {
		uint8_t c = g.clean ? (uint8_t)(data[i] & 0x7F) : data[i];
		char rendered[300];
		int accepted;
		sg_event_t ev;
		unsigned replies = feed(c, &ev, &accepted, rendered);
		if (!g.clean) {
			continue;
		}
		FUZZ_REQUIRE(ev != SG_LOST, "lost characters without a marker");
		if (c == '\r' || c == '\n') {
			line_end(ev, replies, accepted, rendered);
		} else {
			line_char(c);
		}
	}
}
