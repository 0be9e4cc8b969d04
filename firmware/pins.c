#include "firmware/pins.h"

#include "board.h"
#include "firmware/board_pins.h"
#include "firmware/port_io.h"

static uint8_t owner[BOARD_NPORTS * 8];

void pins_init(void)
{
	for (uint8_t i = 0; i < sizeof owner; i++) {
		owner[i] = PIN_FREE;
	}
	/* UART and TWI pins never change hands. */
	owner[board_pin_at(BF_UART_RX, 0)] = PIN_UART;
	owner[board_pin_at(BF_UART_TX, 0)] = PIN_UART;
	owner[board_pin_at(BF_TWI_SCL, 0)] = PIN_TWI;
	owner[board_pin_at(BF_TWI_SDA, 0)] = PIN_TWI;
}

bool pins_can_claim(uint8_t pin, pin_owner_t who)
{
	uint8_t now = owner[pin];
	bool motor_line = now == PIN_MOTOR || now == PIN_MOTOR_IDLE;
	bool motor_wants = who == PIN_MOTOR || who == PIN_MOTOR_IDLE;
	return now == who || now == PIN_FREE || (motor_line && motor_wants)
	       || (now == PIN_MOTOR_IDLE && who == PIN_SERVO);
}

bool pins_claim(uint8_t pin, pin_owner_t who)
{
	if (!pins_can_claim(pin, who)) {
		return false;
	}
	owner[pin] = who;
	return true;
}

void pins_release(uint8_t pin, pin_owner_t who)
{
	if (owner[pin] != who) {
		return;
	}
	if (who == PIN_SERVO && board_pin_has(pin, BF_MOTOR_PWM)) {
		/* Lent by a stopped motor: back to it, driven low. */
		owner[pin] = PIN_MOTOR_IDLE;
		pins_drive(pin, false);
		return;
	}
	owner[pin] = PIN_FREE;
	port_io_dir(PIN_PORT(pin), PIN_MASK(pin), 0);
	pins_level(pin, false);
}

void pins_level(uint8_t pin, bool high)
{
	uint8_t mask = PIN_MASK(pin);
	port_io_write(PIN_PORT(pin), mask, high ? mask : 0);
}

void pins_drive(uint8_t pin, bool high)
{
	pins_level(pin, high);
	port_io_dir(PIN_PORT(pin), PIN_MASK(pin), 0xFF);
}

pin_owner_t pins_owner(uint8_t pin)
{
	return (pin_owner_t)owner[pin];
}

uint8_t pins_gpio_mask(uint8_t port)
{
	uint8_t mask = 0;
	const uint8_t *o = &owner[port * 8];
	/* the line's bit walked along (a shift by the line's number is a loop
	 * on the AVR) */
	for (uint8_t bit = 1; bit; bit = (uint8_t)(bit << 1)) {
		if (*o++ == PIN_FREE) {
			mask |= bit;
		}
	}
	return mask;
}
