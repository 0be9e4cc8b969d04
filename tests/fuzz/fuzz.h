/*
 * libFuzzer harnesses (make fuzz, make fuzz-short; docs/fuzzing.md): what
 * they share. A broken invariant is reported with FUZZ_REQUIRE, which prints
 * why and aborts, so libFuzzer saves the input as a crash.
 */
#ifndef FUZZ_H
#define FUZZ_H

#include <stddef.h>
#include <stdint.h>

void fuzz_fail(const char *file, int line, const char *fmt, ...)
	__attribute__((format(printf, 3, 4), noreturn));

#define FUZZ_REQUIRE(cond, ...) \
	do { \
		if (!(cond)) { \
			fuzz_fail(__FILE__, __LINE__, __VA_ARGS__); \
		} \
	} while (0)

/* --- the input, a byte at a time ------------------------------------------ */

/* What is left of the fuzzer's input. */
typedef struct {
	const uint8_t *at;
	size_t left;
} fuzz_input_t;

/* The input's next byte; 0 once it is used up, so that an input may end
 * anywhere. */
static inline uint8_t fuzz_byte(fuzz_input_t *in)
{
	if (!in->left) {
		return 0;
	}
	in->left--;
	return *in->at++;
}

/* --- the serial gateway (fuzz_gate.c; harnesses fuzz-parse, fuzz-exec) --- */

/* What the board under the gateway provides. */
void fuzz_gate_boot(void);          /* power-on: hardware fakes, regmap */
void fuzz_gate_save(void);          /* a line begins: remember the state */
int fuzz_gate_unchanged(void);      /* nothing changed since fuzz_gate_save */
void fuzz_gate_after_line(void);    /* board invariants after each line */

/* Feeds the input to the parser and executor, checking every reply. The
 * first byte % 3 chooses: 0, the rest with bit 7 cleared straight into the
 * parser (no lost-run marks: the line/reply model holds line by line);
 * 1, the bytes as they are (made-up marks too: replies are checked for form
 * only); 2, the bytes through the receive ring (sg_rx.c), taken out at a
 * rate the first byte's bits 2-7 set, so that it overflows. */
void fuzz_gate_run(const uint8_t *data, size_t size);

/* --- a board's real drivers over hw_fakes (fuzz_board.c) --------------- */

/* Registers in the map (first unmapped one), from the introspection records. */
uint8_t fuzz_board_nregs(void);

/* Remember the pins of fixed functions (UART, TWI, SPI bus, servo counter
 * clocks) after boot; check that nothing moved them since. */
void fuzz_board_fixed_save(void);
void fuzz_board_fixed_check(void);

#endif
