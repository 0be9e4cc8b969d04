/* The serial gateway front end: UART characters in, replies out. */
#include "firmware/front.h"

#include "firmware/twi_master.h"
#include "firmware/uart.h"
#include "serialgate/sg_exec.h"
#include "serialgate/sg_parse.h"

_Static_assert(UART_RX_LOST == SG_CHAR_LOST, "UART and parser agree on the lost marker");

static sg_parser_t parser;

void sg_out(uint8_t c)
{
	uart_putc(c);
}

void front_init(void)
{
	uart_init();
	twi_init();
	sg_parse_init(&parser);
	sg_exec_init();
}

void front_poll(void)
{
	if (uart_line_poll()) {
		/* No rate yet (autobaud): a line begun before is noise. */
		sg_parse_init(&parser);
		return;
	}
	int16_t c = uart_getc();
	if (c < 0) {
		return;
	}
	sg_event_t ev = sg_parse_char(&parser, (uint8_t)c);
	if (ev == SG_REQUEST) {
		if (parser.err == SG_OK) {
			uart_line_confirm();	/* a good request proves the rate */
		}
		sg_exec(&parser);
	} else if (ev == SG_LOST) {
		sg_exec_lost(&parser);
	}
}
