/*
 * The C library's pure part (host/c/orfa_line.c): request lines as the
 * gateway must receive them, the limits refused before anything is sent,
 * and reply lines parsed into one result per frame, ERROR and malformed
 * replies included (docs/c-library.md, docs/protocol.md).
 */
#include <stdio.h>
#include <string.h>

#include "orfa_line.h"

#include "check.h"

static orfa_req_t req;
static orfa_reply_t out[ORFA_FRAMES_MAX];

/* A request of one write [00 first] and one read of `count`, ended. */
static int intro_req(uint8_t addr, uint8_t first, size_t count)
{
	uint8_t buf[2] = {0x00, first};
	int rc;

	orfa_req_start(&req);
	rc = orfa_req_write(&req, addr, buf, 2);
	if (rc == ORFA_OK) {
		rc = orfa_req_read(&req, addr, count);
	}
	if (rc == ORFA_OK) {
		rc = orfa_req_end(&req);
	}
	return rc;
}

static int parse(const char *line, int *code)
{
	return orfa_reply_parse(&req, line, strlen(line), out, code);
}

static void test_format(void)
{
	uint8_t data[3] = {0x00, 0x11, 0x12};

	CHECK(intro_req(0xAA, 0, 1) == ORFA_OK, "count request");
	CHECK(strcmp(req.text, "SAA0000SAB01P\n") == 0, "text %s", req.text);
	CHECK(req.len == 14, "len %zu", req.len);
	CHECK(req.reply_len == strlen("SWAASR07P"), "reply_len %zu", req.reply_len);
	CHECK(req.nframes == 2 && req.frames[0].address == 0xAA && req.frames[0].count == 2 &&
	      req.frames[1].address == 0xAB && req.frames[1].count == 1, "frames");

	/* the manual's example: write 00 11 12 to register 20 of device 10 */
	orfa_req_start(&req);
	CHECK(orfa_req_write(&req, 0x10, (const uint8_t[]){0x20}, 1) == ORFA_OK, "reg");
	orfa_req_start(&req);
	CHECK(orfa_req_write(&req, 0x10, (const uint8_t[]){0x20, 0x00, 0x11, 0x12}, 4) == ORFA_OK,
	      "write");
	CHECK(orfa_req_end(&req) == ORFA_OK, "end");
	CHECK(strcmp(req.text, "S1020001112P\n") == 0, "text %s", req.text);

	/* bit 0 of the address: cleared for writes, set for reads */
	orfa_req_start(&req);
	CHECK(orfa_req_write(&req, 0xAB, data, 0) == ORFA_OK, "probe");
	CHECK(orfa_req_read(&req, 0xA0, 3) == ORFA_OK, "read");
	CHECK(orfa_req_end(&req) == ORFA_OK, "end");
	CHECK(strcmp(req.text, "SAASA103P\n") == 0, "text %s", req.text);

	/* a write of no bytes: the address probe */
	orfa_req_start(&req);
	CHECK(orfa_req_write(&req, 0x42, NULL, 0) == ORFA_OK, "probe");
	CHECK(orfa_req_end(&req) == ORFA_OK, "end");
	CHECK(strcmp(req.text, "S42P\n") == 0, "text %s", req.text);
	CHECK(req.reply_len == 3, "SWP: %zu", req.reply_len);

	/* the one-line commands */
	CHECK(orfa_req_version(&req) == ORFA_OK && strcmp(req.text, "V\n") == 0, "V");
	CHECK(orfa_req_clear(&req) == ORFA_OK && strcmp(req.text, "X\n") == 0, "X");
	CHECK(orfa_req_local(&req, -1) == ORFA_OK && strcmp(req.text, "L\n") == 0, "L");
	CHECK(orfa_req_local(&req, 0x21) == ORFA_OK && strcmp(req.text, "L21\n") == 0, "L21");
	CHECK(orfa_req_clock(&req, -1) == ORFA_OK && strcmp(req.text, "C\n") == 0, "C");
	CHECK(orfa_req_clock(&req, 400) == ORFA_OK && strcmp(req.text, "C0190\n") == 0, "C0190");
	CHECK(orfa_req_clock(&req, 0xFFFF) == ORFA_OK && strcmp(req.text, "CFFFF\n") == 0, "CFFFF");
}

static void test_limits(void)
{
	uint8_t big[200];
	size_t i;

	memset(big, 0x5A, sizeof(big));
	/* ten introspection records fill the 127-character reply exactly */
	CHECK(intro_req(0xAA, 1, 60) == ORFA_OK, "10 records");
	CHECK(strcmp(req.text, "SAA0001SAB3CP\n") == 0, "text %s", req.text);
	CHECK(req.reply_len == 127, "reply_len %zu", req.reply_len);
	/* eleven do not: refused, and the request as a whole */
	CHECK(intro_req(0xAA, 1, 61) == ORFA_E_LIMIT, "61 bytes");
	CHECK(orfa_req_end(&req) == ORFA_E_LIMIT, "sticky");
	CHECK(req.len == 7 && strcmp(req.text, "SAA0001") == 0, "nothing added: %s", req.text);
	CHECK(intro_req(0xAA, 1, 255) == ORFA_E_LIMIT, "255 bytes");
	CHECK(intro_req(0xAA, 1, 100000) == ORFA_E_LIMIT, "huge count");

	/* the 128-character request: a write of 62 bytes fits, 63 not */
	orfa_req_start(&req);
	CHECK(orfa_req_write(&req, 0x10, big, 62) == ORFA_OK, "62");
	CHECK(orfa_req_end(&req) == ORFA_OK, "end");
	CHECK(req.len == 129 && req.text[127] == 'P' && req.text[128] == '\n', "len %zu", req.len);
	orfa_req_start(&req);
	CHECK(orfa_req_write(&req, 0x10, big, 63) == ORFA_E_LIMIT, "63");
	CHECK(orfa_req_end(&req) == ORFA_E_LIMIT, "end");
	orfa_req_start(&req);
	CHECK(orfa_req_write(&req, 0x10, big, sizeof(big)) == ORFA_E_LIMIT, "200");

	/* frames: 42 probes are 126 characters and P */
	orfa_req_start(&req);
	for (i = 0; i < 42; i++) {
		CHECK(orfa_req_write(&req, 0x20, NULL, 0) == ORFA_OK, "probe %zu", i);
	}
	CHECK(orfa_req_write(&req, 0x20, NULL, 0) == ORFA_E_LIMIT, "43rd");
	CHECK(orfa_req_end(&req) == ORFA_E_LIMIT, "refused");

	/* 25 reads are 125 characters and P: a probe more is 129 */
	orfa_req_start(&req);
	for (i = 0; i < 25; i++) {
		CHECK(orfa_req_read(&req, 0x20, 1) == ORFA_OK, "read %zu", i);
	}
	CHECK(orfa_req_write(&req, 0x20, NULL, 0) == ORFA_E_LIMIT, "request over 128");

	/* read count 0 is the gateway's ERROR 04: refused here */
	orfa_req_start(&req);
	CHECK(orfa_req_read(&req, 0x20, 0) == ORFA_E_ARG, "count 0");
	CHECK(orfa_req_end(&req) == ORFA_E_ARG, "refused");
	/* nothing to send */
	orfa_req_start(&req);
	CHECK(orfa_req_end(&req) == ORFA_E_ARG, "empty");
	/* ended: no more frames, no second end */
	CHECK(intro_req(0xAA, 0, 1) == ORFA_OK, "ok");
	CHECK(orfa_req_write(&req, 0xAA, NULL, 0) == ORFA_E_ARG, "after end");
	CHECK(orfa_req_end(&req) == ORFA_E_ARG, "second end");
	/* values the gateway refuses */
	CHECK(orfa_req_local(&req, 0) == ORFA_E_ARG, "L00");
	CHECK(orfa_req_local(&req, 1) == ORFA_E_ARG, "L01");
	CHECK(orfa_req_local(&req, 0x100) == ORFA_E_ARG, "L100");
	CHECK(orfa_req_clock(&req, 0) == ORFA_E_ARG, "C0000");
	CHECK(orfa_req_clock(&req, 0x10000) == ORFA_E_ARG, "C10000");
	CHECK(orfa_req_write(NULL, 0, NULL, 0) == ORFA_E_ARG, "NULL");
}

static void test_parse(void)
{
	int code = -1;
	int n;
	char line[ORFA_REPLY_MAX + 8];

	CHECK(intro_req(0xAA, 0, 1) == ORFA_OK, "request");
	n = parse("SWAASR07P", &code);
	CHECK(n == 2, "results %d", n);
	CHECK(out[0].type == ORFA_REPLY_WRITE && out[0].address == 0xAA && out[0].size == 2 &&
	      out[0].frame == 0 && out[0].last == 0, "SW result");
	CHECK(out[1].type == ORFA_REPLY_READ && out[1].address == 0xAB && out[1].size == 1 &&
	      out[1].data[0] == 0x07 && out[1].frame == 1 && out[1].last == 1, "SR result");
	CHECK(parse("SWAASR0aP", &code) == 2 && out[1].data[0] == 0x0A, "lower case hex");

	/* ERROR xx: the code, no results */
	CHECK(parse("ERROR 06", &code) == ORFA_E_REPLY && code == 6, "ERROR 06: code %d", code);
	CHECK(parse("ERROR 04", &code) == ORFA_E_REPLY && code == 4, "ERROR 04");
	CHECK(parse("ERROR 6", &code) == ORFA_E_PROTOCOL, "one digit");
	CHECK(parse("ERROR XY", &code) == ORFA_E_PROTOCOL, "not hex");
	CHECK(parse("ERROR 060", &code) == ORFA_E_PROTOCOL, "three digits");

	/* lines that do not answer S AA 00 00 S AB 01 P */
	CHECK(parse("SWASR07P", &code) == ORFA_E_PROTOCOL, "one A short");
	CHECK(parse("SWAAASR07P", &code) == ORFA_E_PROTOCOL, "one A over");
	CHECK(parse("SWAASR0P", &code) == ORFA_E_PROTOCOL, "half a byte");
	CHECK(parse("SWAASR0707P", &code) == ORFA_E_PROTOCOL, "a byte over");
	CHECK(parse("SWAASR07", &code) == ORFA_E_PROTOCOL, "no P");
	CHECK(parse("SWAASR07PP", &code) == ORFA_E_PROTOCOL, "after P");
	CHECK(parse("SRAASW07P", &code) == ORFA_E_PROTOCOL, "frames swapped");
	CHECK(parse("SWAASR0GP", &code) == ORFA_E_PROTOCOL, "not hex");
	CHECK(parse("SWAA", &code) == ORFA_E_PROTOCOL, "cut short");
	CHECK(parse("", &code) == ORFA_E_PROTOCOL, "empty");
	CHECK(parse("V1.1", &code) == ORFA_E_PROTOCOL, "another request's reply");

	/* ten records: the 127-character reply */
	CHECK(intro_req(0xAA, 1, 60) == ORFA_OK, "request");
	strcpy(line, "SWAASR");
	for (n = 0; n < 60; n++) {
		sprintf(line + 6 + 2 * n, "%02X", n);
	}
	strcat(line, "P");
	CHECK(strlen(line) == 127, "len %zu", strlen(line));
	n = parse(line, &code);
	CHECK(n == 2 && out[1].size == 60 && out[1].data[0] == 0 && out[1].data[59] == 59,
	      "60 bytes: %d", n);
	/* a line over 127 characters is no reply */
	strcpy(line + 126, "00P");
	CHECK(parse(line, &code) == ORFA_E_PROTOCOL, "128 characters");

	/* a probe: SWP */
	orfa_req_start(&req);
	orfa_req_write(&req, 0x42, NULL, 0);
	orfa_req_end(&req);
	CHECK(parse("SWP", &code) == 1 && out[0].type == ORFA_REPLY_WRITE && out[0].size == 0 &&
	      out[0].last == 1, "SWP");

	/* the one-line commands */
	orfa_req_version(&req);
	CHECK(parse("V1.1", &code) == 1 && out[0].type == ORFA_REPLY_VERSION && out[0].size == 3 &&
	      memcmp(out[0].data, "1.1", 3) == 0, "V1.1");
	CHECK(parse("V", &code) == ORFA_E_PROTOCOL, "V alone");
	CHECK(parse("ERROR 02", &code) == ORFA_E_REPLY && code == 2, "V: ERROR 02");
	orfa_req_clear(&req);
	CHECK(parse("X", &code) == 1 && out[0].type == ORFA_REPLY_CLEAR && out[0].size == 0, "X");
	CHECK(parse("XX", &code) == ORFA_E_PROTOCOL, "XX");
	orfa_req_local(&req, -1);
	CHECK(parse("LAA", &code) == 1 && out[0].type == ORFA_REPLY_LOCAL && out[0].size == 1 &&
	      out[0].data[0] == 0xAA, "LAA");
	CHECK(parse("LA", &code) == ORFA_E_PROTOCOL, "LA");
	CHECK(parse("SWP", &code) == ORFA_E_PROTOCOL, "L: SWP");
	orfa_req_clock(&req, -1);
	CHECK(parse("C0063", &code) == 1 && out[0].type == ORFA_REPLY_CLOCK && out[0].size == 2 &&
	      out[0].data[0] == 0x00 && out[0].data[1] == 0x63, "C0063");
	CHECK(parse("C63", &code) == ORFA_E_PROTOCOL, "C63");

	/* a request not ended has no reply to parse */
	orfa_req_start(&req);
	CHECK(parse("SWP", &code) == ORFA_E_ARG, "not ended");
}

static void test_strings(void)
{
	int e;

	for (e = ORFA_E_FULL; e <= ORFA_OK; e++) {
		CHECK(strcmp(orfa_strerror(e), "unknown error") != 0, "strerror(%d)", e);
	}
	CHECK(strcmp(orfa_strerror(-100), "unknown error") == 0, "strerror(-100)");
	for (e = 1; e <= 7; e++) {
		CHECK(strcmp(orfa_code_str(e), "unknown protocol error") != 0, "code %d", e);
	}
	CHECK(strncmp(orfa_code_str(6), "no ACK for an address byte", 26) == 0, "code 6: %s", orfa_code_str(6));
	CHECK(strcmp(orfa_code_str(0x42), "unknown protocol error") == 0, "code 42");
}

int main(void)
{
	test_format();
	test_limits();
	test_parse();
	test_strings();
	printf("orfa-line: %d checks, %d failures\n", checks, failures);
	return failures != 0;
}
