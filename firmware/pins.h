/*
 * Pin ownership: every pin belongs to at most one function at a time
 * (docs/registers.md, "Register maps"). GPIO has every pin of its ports that
 * nobody else holds; a driver that wants a pin held by another function is
 * refused.
 */
#ifndef ORFA_PINS_H
#define ORFA_PINS_H

#include <stdbool.h>
#include <stdint.h>

/* A pin as one byte: port index (0 = A) * 8 + line. */
#define PIN_ID(port_letter, line) ((uint8_t)((((port_letter) - 'A') << 3) | (line)))
#define PIN_PORT(pin) ((uint8_t)((pin) >> 3))
#define PIN_MASK(pin) ((uint8_t)(1u << ((pin) & 7)))


typedef enum {
	PIN_FREE = 0,     /* GPIO's */
	PIN_UART,
	PIN_TWI,
	PIN_SPI,          /* SCK, MOSI, MISO, SS */
	PIN_SPI_CS,       /* a chip-select line bound to an SPI channel */
	PIN_MOTOR,        /* motor output in use */
	PIN_MOTOR_IDLE,   /* motor PWM output of a stopped motor: low, may be lent */
	PIN_SERVO,
	PIN_SERVO_CLK,    /* M128-S counter clocks and reset */
	PIN_ADC,
} pin_owner_t;

/* Claims the fixed functions (UART, TWI) from the board's pin map. */
void pins_init(void);

/* Takes `pin` for `who`: true if it was free, already `who`'s, or a stopped
 * motor's PWM output lent to a servo. False, and nothing changes, otherwise. */
bool pins_claim(uint8_t pin, pin_owner_t who);

/* Whether pins_claim(pin, who) would succeed; changes nothing. A write that
 * needs several pins checks them all first: undoing a claim with
 * pins_release would reset a GPIO line the write never had. */
bool pins_can_claim(uint8_t pin, pin_owner_t who);

/* Gives a pin back: a lent motor output returns to the stopped motor (output
 * low), any other pin to GPIO as an input without pull-up (its reset state).
 * Does nothing if `who` does not hold it. */
void pins_release(uint8_t pin, pin_owner_t who);

pin_owner_t pins_owner(uint8_t pin);

/* The pin's output latch high or low (a level when it is an output, the
 * pull-up when an input). */
void pins_level(uint8_t pin, bool high);

/* The pin an output at that level: the latch first, so it never shows the
 * other one. */
void pins_drive(uint8_t pin, bool high);

/* The lines of `port` that GPIO may change. */
uint8_t pins_gpio_mask(uint8_t port);

#endif
