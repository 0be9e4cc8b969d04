/*
 * OR-AVR-M32-D: what only this board has. Servos on port pins (A, B2-B3,
 * C4-C7, D4-D5), ADC on port A shared with servos 0-7, motors whose PWM
 * lines are servo channels 14/15, UART on D0-D1, TWI on C0-C1, SPI on B4-B7.
 */
#include <stdio.h>

#include "drv_test.h"

enum { PA, PB, PC, PD };

/* docs/registers.md, register map and introspection records. */
const board_t B = {
	.name = "m32d",
	.nregs = 0x16,
	.ndrivers = 7,
	.intro = "00 00 01 00 00 02  00 20 01 01 02 08  00 01 01 01 0A 02"
		 "  00 40 01 01 0C 02  00 60 01 01 0E 04  00 31 02 00 12 02"
		 "  00 02 01 00 14 02",
	.gpio_nports = 4,
	.gpio_value = 0x02,
	.gpio_mode = 0x06,
	.gpio_port = { PA, PB, PC, PD },
	.spi_data = 0x0A,
	.spi_config = 0x0B,
	.adc_rc = 0x0C,
	.adc_rd = 0x0D,
	.adc_port = PA,
	.adc_gpio = 0,
	.servo_rs = 0x12,
	.servo_sp = 0x13,
	.servo_channels = 16,
};

#define VAL(p) (0x02 + (p))
#define MODE(p) (0x06 + (p))
#define PWM1 0x0E
#define PWM2 0x0F
#define DIR1 0x10
#define DIR2 0x11
#define RS 0x12
#define SP 0x13
#define SPI_CFG 0x0B
#define ADC_RC 0x0C

static void test_gpio_held(void)
{
	boot();
	/* Fixed functions own their lines from reset. */
	CHECK_EQ(pins_owner(PIN(PD, 0)), PIN_UART);
	CHECK_EQ(pins_owner(PIN(PD, 1)), PIN_UART);
	CHECK_EQ(pins_owner(PIN(PC, 0)), PIN_TWI);
	CHECK_EQ(pins_owner(PIN(PC, 1)), PIN_TWI);
	for (unsigned l = 4; l < 8; l++) {
		CHECK_EQ(pins_owner(PIN(PB, l)), PIN_SPI);
	}
	CHECK_EQ(pins_owner(PIN(PB, 0)), PIN_MOTOR);
	CHECK_EQ(pins_owner(PIN(PB, 1)), PIN_MOTOR);
	CHECK_EQ(pins_owner(PIN(PD, 5)), PIN_MOTOR_IDLE);
	CHECK_EQ(pins_owner(PIN(PD, 4)), PIN_MOTOR_IDLE);

	/* All outputs, all high: only GPIO's lines move. */
	for (unsigned p = PA; p <= PD; p++) {
		WRITE(MODE(p), "FF", REG_OK);
		WRITE(VAL(p), "FF", REG_OK);
	}
	CHECK_EQ(port_ddr[PA], 0xFF);
	CHECK_EQ(port_ddr[PB], 0x0C);   /* not DIR1/2 (0-1), not SPI (4-7) */
	CHECK_EQ(port_ddr[PC], 0xFC);   /* not TWI */
	CHECK_EQ(port_ddr[PD], 0xCC);   /* not UART, not PWM2/PWM1 (4-5) */
	CHECK_EQ(port_out[PA], 0xFF);
	CHECK_EQ(port_out[PB], 0x0C);
	CHECK_EQ(port_out[PC], 0xFC);
	CHECK_EQ(port_out[PD], 0xCC);
	READ(MODE(PB), 1, "0C");
	READ(MODE(PD), 1, "CC");
	/* A mask naming only held lines changes nothing, and is no error. */
	WRITE(MODE(PD), "00 33", REG_OK);
	WRITE(VAL(PB), "00 F3", REG_OK);
	CHECK_EQ(port_ddr[PD], 0xCC);
	CHECK_EQ(port_out[PB], 0x0C);
	/* Value reads give all eight pins, held lines included: the UART
	 * lines are inputs here (nothing set them), driven high outside. */
	port_ext[PD] = 0x03;
	READ(VAL(PD), 1, "CF");

	/* A pulsing servo's pin: output low, out of GPIO's reach; back to
	 * GPIO (input, no pull-up) when the channel is turned off. */
	WRITE(SP, "02 05 DC 0C 05 DC 08 05 DC", REG_OK);
	CHECK_EQ(pins_owner(PIN(PA, 2)), PIN_SERVO);
	CHECK_EQ(pins_owner(PIN(PB, 3)), PIN_SERVO);
	CHECK_EQ(pins_owner(PIN(PC, 7)), PIN_SERVO);
	CHECK_EQ(port_out[PA], 0xFB);
	CHECK_EQ(port_ddr[PA], 0xFF);
	CHECK_EQ(port_out[PB], 0x04);
	CHECK_EQ(port_out[PC], 0x7C);
	WRITE(VAL(PA), "FF", REG_OK);
	WRITE(MODE(PB), "00", REG_OK);
	WRITE(MODE(PC), "00", REG_OK);
	CHECK_EQ(port_out[PA], 0xFB);
	CHECK_EQ(port_ddr[PB], 0x08);
	CHECK_EQ(port_ddr[PC], 0x80);
	READ(MODE(PC), 1, "80");
	WRITE(SP, "02 00 00 0C 00 00 08 00 00", REG_OK);
	CHECK_EQ(pins_owner(PIN(PA, 2)), PIN_FREE);
	CHECK_EQ(port_out[PA], 0xFB);
	CHECK_EQ(port_ddr[PA], 0xFB);
	CHECK_EQ(port_ddr[PB], 0x00);
	CHECK_EQ(port_ddr[PC], 0x00);
	WRITE(MODE(PA), "FF", REG_OK);
	WRITE(VAL(PA), "FF", REG_OK);
	CHECK_EQ(port_ddr[PA], 0xFF);
	CHECK_EQ(port_out[PA], 0xFF);

	/* Enabled ADC lines: inputs without pull-up, out of GPIO's reach. */
	WRITE(ADC_RC, "01 20", REG_OK);
	CHECK_EQ(port_ddr[PA], 0xDF);
	CHECK_EQ(port_out[PA], 0xDF);
	WRITE(MODE(PA), "FF", REG_OK);
	WRITE(VAL(PA), "FF", REG_OK);
	CHECK_EQ(port_ddr[PA], 0xDF);
	CHECK_EQ(port_out[PA], 0xDF);
	/* A bound chip select too. */
	WRITE(SPI_CFG, "00 02 02", REG_OK);
	WRITE(MODE(PC), "00", REG_OK);
	WRITE(VAL(PC), "00", REG_OK);
	CHECK_EQ(port_ddr[PC], 0x04);
	CHECK_EQ(port_out[PC], 0x04);
}

/* A write that needs a pin another function holds changes nothing, also
 * not the pins it could have had. */
static void test_all_or_nothing(void)
{
	/* docs/registers.md: an ADC channel on PA3 refuses servo 2+3. PA2 is a
	 * GPIO output driven high (an LED, say): it must stay so. */
	boot();
	WRITE(MODE(PA), "04 04", REG_OK);
	WRITE(VAL(PA), "04 04", REG_OK);
	WRITE(ADC_RC, "00 08", REG_OK);
	WRITE(SP, "07 05 DC", REG_OK);
	REFUSED(SP, REG_PIN_BUSY, "02 05 DC 03 05 DC");
	CHECK_EQ(port_ddr[PA], 0x84);
	CHECK_EQ(port_out[PA], 0x04);
	CHECK_EQ(pins_owner(PIN(PA, 2)), PIN_FREE);
	REFUSED(SP, REG_PIN_BUSY, "03 05 DC 02 05 DC");
	/* Turning a channel off in the same write is undone as well. */
	REFUSED(SP, REG_PIN_BUSY, "07 00 00 03 05 DC");
	READ(SP, 16, "00 00 00 00 00 00 00 00 00 00 00 00 00 00 05 DC");
	/* Without channel 3 it goes through. */
	WRITE(SP, "02 05 DC", REG_OK);
	CHECK_EQ(pins_owner(PIN(PA, 2)), PIN_SERVO);
	CHECK_EQ(port_out[PA], 0x00);

	/* The ADC likewise: PA0 a GPIO output high, PA1 a servo's. */
	boot();
	WRITE(MODE(PA), "01 01", REG_OK);
	WRITE(VAL(PA), "01 01", REG_OK);
	WRITE(SP, "01 05 DC", REG_OK);
	REFUSED(ADC_RC, REG_PIN_BUSY, "01 03");
	CHECK_EQ(port_ddr[PA], 0x03);
	CHECK_EQ(port_out[PA], 0x01);
	READ(ADC_RC, 2, "00 00");
	/* Also when it already has lines: they stay, settings stay. */
	WRITE(ADC_RC, "05 10", REG_OK);
	REFUSED(ADC_RC, REG_PIN_BUSY, "01 13");
	READ(ADC_RC, 2, "05 10");
	CHECK_EQ(hw.adc_mask, 0x10);
	CHECK_EQ(hw.adc_refs, 1);
	/* A chip select refuses it too. */
	WRITE(SPI_CFG, "02 00 06", REG_OK);
	REFUSED(ADC_RC, REG_PIN_BUSY, "00 40");

	/* Servo on a line that is a chip select, an ADC line, or neither. */
	REFUSED(SP, REG_PIN_BUSY, "06 05 DC", "04 05 DC", "00 05 DC 04 05 DC");

	/* Chip selects on lines other functions hold: 03, nothing changes. */
	REFUSED(SPI_CFG, REG_PIN_BUSY,
		"00 00 01",  /* servo 1 */
		"00 00 04",  /* ADC 4 */
		"00 03 00",  /* RXD */
		"00 03 01",  /* TXD */
		"00 02 00",  /* SCL */
		"00 02 01",  /* SDA */
		"00 01 04",  /* SS */
		"00 01 07",  /* SCK */
		"00 01 00",  /* DIR1 */
		"00 03 05",  /* PWM1, stopped */
		"00 03 04",  /* PWM2, stopped */
		"02 00 01"); /* a bound channel keeps its line */
	READ(SPI_CFG, 9, "02 FF FF FF FF 00 06 FF FF");
}

/* The link-loss failsafe stops both motors (PWM 0, directions kept), as a
 * host's write of 00 00 to PWM1 would; a servo on a motor's line goes off. */
static void test_motor_failsafe(void)
{
	boot();
	WRITE(PWM1, "80 60 01 00", REG_OK);
	regmap_safe();
	READ(PWM1, 4, "00 00 01 00");
	CHECK_EQ(hw.motor_pwm[0], 0);
	CHECK_EQ(hw.motor_pwm[1], 0);
	CHECK_EQ(hw.motor_dir[0], 1);
	CHECK_EQ(pins_owner(PIN(PD, 5)), PIN_MOTOR_IDLE);
	CHECK_EQ(pins_owner(PIN(PD, 4)), PIN_MOTOR_IDLE);
	/* servo 14 on PWM1's line */
	WRITE(SP, "0E 05 DC", REG_OK);
	CHECK_EQ(pins_owner(PIN(PD, 5)), PIN_SERVO);
	regmap_safe();
	WRITE(SP, "0E", REG_OK);
	READ(SP, 2, "00 00");
	CHECK_EQ(pins_owner(PIN(PD, 5)), PIN_MOTOR_IDLE);
	WRITE(PWM1, "10", REG_OK);
}

static void test_motors(void)
{
	boot();
	CHECK_EQ(hw.motor_inits, 1);
	READ(PWM1, 4, "00 00 00 00");
	/* 80 60 00 01 to PWM1 sets all four. */
	WRITE(PWM1, "80 60 00 01", REG_OK);
	CHECK_EQ(hw.motor_applies, 1);
	CHECK_EQ(hw.motor_pwm[0], 0x80);
	CHECK_EQ(hw.motor_pwm[1], 0x60);
	CHECK_EQ(hw.motor_dir[0], 0);
	CHECK_EQ(hw.motor_dir[1], 1);
	CHECK_EQ(hw.motor_lines, 0x03);
	CHECK_EQ(pins_owner(PIN(PD, 5)), PIN_MOTOR);
	CHECK_EQ(pins_owner(PIN(PD, 4)), PIN_MOTOR);
	/* Reading register r gives r..DIR2; more asks again from r. */
	READ(PWM1, 4, "80 60 00 01");
	READ(PWM2, 3, "60 00 01");
	READ(DIR1, 2, "00 01");
	READ(DIR2, 1, "01");
	READ(PWM1, 2, "80 60");
	READ(DIR1, 5, "00 01 00 01 00");
	/* Partial writes: k bytes to r set r..r+k-1, the others stay. */
	WRITE(PWM2, "20 01", REG_OK);
	READ(PWM1, 4, "80 20 01 01");
	CHECK_EQ(hw.motor_pwm[0], 0x80);
	CHECK_EQ(hw.motor_pwm[1], 0x20);
	CHECK_EQ(hw.motor_dir[0], 1);
	CHECK_EQ(hw.motor_dir[1], 1);
	WRITE(DIR2, "00", REG_OK);
	WRITE(PWM1, "FF", REG_OK);
	READ(PWM1, 4, "FF 20 01 00");
	CHECK_EQ(hw.motor_pwm[0], 0xFF);
	CHECK_EQ(hw.motor_dir[1], 0);
	/* PWM 0 stops a motor: its line is idle (lendable), still driven. */
	WRITE(PWM2, "00", REG_OK);
	CHECK_EQ(pins_owner(PIN(PD, 4)), PIN_MOTOR_IDLE);
	CHECK_EQ(hw.motor_lines, 0x03);
	CHECK_EQ(hw.motor_pwm[1], 0);

	/* Rejections change nothing, the hardware records included. */
	REFUSED(PWM1, REG_BAD_LENGTH, "00 00 00 00 00", "");
	REFUSED(PWM2, REG_BAD_LENGTH, "00 00 00 00");
	REFUSED(DIR1, REG_BAD_LENGTH, "00 00 00");
	REFUSED(DIR2, REG_BAD_LENGTH, "00 00");
	REFUSED(DIR1, REG_BAD_VALUE, "02");
	REFUSED(DIR2, REG_BAD_VALUE, "FF");
	REFUSED(PWM1, REG_BAD_VALUE, "00 00 00 02", "10 10 80 00");
	/* GPIO never reaches the motor lines. */
	WRITE(MODE(PD), "00", REG_OK);
	WRITE(MODE(PB), "00", REG_OK);
	CHECK_EQ(pins_gpio_mask(PD), 0xCC);
	CHECK_EQ(pins_gpio_mask(PB), 0x0C);

	/* Lending. Motor 2 stopped: servo 15 (PD4) may pulse. */
	WRITE(SP, "0F 05 DC", REG_OK);
	CHECK_EQ(pins_owner(PIN(PD, 4)), PIN_SERVO);
	CHECK_EQ(hw.servo_width[15], 1500);
	/* While it pulses motor 2 cannot run: 03, nothing changes (motor 1
	 * included, the write is all or nothing). */
	REFUSED(PWM2, REG_PIN_BUSY, "01");
	REFUSED(PWM1, REG_PIN_BUSY, "40 FF 00 00");
	/* PWM2 = 0 is fine; motor 2's line is left to the servo. */
	WRITE(PWM1, "40 00 01 01", REG_OK);
	CHECK_EQ(hw.motor_lines, 0x01);
	CHECK_EQ(hw.motor_pwm[0], 0x40);
	CHECK_EQ(hw.motor_dir[1], 1);
	CHECK_EQ(pins_owner(PIN(PD, 4)), PIN_SERVO);
	/* Motor 1 runs: servo 14 (PD5) is refused, 03, nothing changes. */
	REFUSED(SP, REG_PIN_BUSY, "0E 05 DC", "0F 07 D0 0E 05 DC");
	/* Motor 1 stops: servo 14 may take PD5 now. */
	WRITE(PWM1, "00", REG_OK);
	CHECK_EQ(pins_owner(PIN(PD, 5)), PIN_MOTOR_IDLE);
	WRITE(SP, "0E 05 DC", REG_OK);
	CHECK_EQ(pins_owner(PIN(PD, 5)), PIN_SERVO);
	READ(RS, 2, "C0 00");
	/* Direction writes still work; neither PWM line is the motors'. */
	WRITE(DIR1, "00 00", REG_OK);
	CHECK_EQ(hw.motor_lines, 0x00);
	CHECK_EQ(hw.motor_dir[0], 0);
	REFUSED(PWM1, REG_PIN_BUSY, "01");
	/* Servo 15 off: PD4 goes back to the stopped motor, low output. */
	WRITE(SP, "0F 00 00", REG_OK);
	CHECK_EQ(pins_owner(PIN(PD, 4)), PIN_MOTOR_IDLE);
	CHECK_EQ(port_ddr[PD] & 0x10, 0x10);
	CHECK_EQ(port_out[PD] & 0x10, 0x00);
	CHECK_EQ(pins_gpio_mask(PD), 0xCC);
	/* ... and motor 2 may run again; motor 1 still may not. */
	WRITE(PWM2, "C0", REG_OK);
	CHECK_EQ(hw.motor_lines, 0x02);
	CHECK_EQ(hw.motor_pwm[1], 0xC0);
	CHECK_EQ(pins_owner(PIN(PD, 4)), PIN_MOTOR);
	WRITE(PWM1, "01", REG_PIN_BUSY);
	/* Servo 15 now refused. */
	WRITE(SP, "0F 05 DC", REG_PIN_BUSY);
	/* Servo 14 off, motor 1 runs. */
	WRITE(SP, "0E 00 00", REG_OK);
	CHECK_EQ(pins_owner(PIN(PD, 5)), PIN_MOTOR_IDLE);
	WRITE(PWM1, "01", REG_OK);
	CHECK_EQ(hw.motor_lines, 0x03);
	READ(PWM1, 4, "01 C0 00 00");
	READ(RS, 2, "00 00");
}

static void test_servo_pins(void)
{
	boot();
	/* Every channel's pin from the board's map, claimed on, freed off. */
	static const uint8_t pin[16] = {
		PIN(PA, 0), PIN(PA, 1), PIN(PA, 2), PIN(PA, 3), PIN(PA, 4), PIN(PA, 5), PIN(PA, 6),
		PIN(PA, 7), PIN(PC, 7), PIN(PC, 6), PIN(PC, 5), PIN(PC, 4), PIN(PB, 3), PIN(PB, 2),
		PIN(PD, 5), PIN(PD, 4),
	};
	char t[16];
	for (unsigned ch = 0; ch < 16; ch++) {
		snprintf(t, sizeof t, "%02X 03 E8", ch);
		WRITE(SP, t, REG_OK);
		CHECK_EQ(pins_owner(pin[ch]), PIN_SERVO);
		CHECK_EQ(port_ddr[pin[ch] >> 3] & (1u << (pin[ch] & 7)), 1u << (pin[ch] & 7));
	}
	CHECK_EQ(pins_gpio_mask(PA), 0x00);
	CHECK_EQ(pins_gpio_mask(PB), 0x00);
	CHECK_EQ(pins_gpio_mask(PC), 0x0C);
	READ(RS, 2, "FF FF");
	for (unsigned ch = 0; ch < 14; ch++) {
		snprintf(t, sizeof t, "%02X 00 00", ch);
		WRITE(SP, t, REG_OK);
		CHECK_EQ(pins_owner(pin[ch]), PIN_FREE);
		CHECK_EQ(port_ddr[pin[ch] >> 3] & (1u << (pin[ch] & 7)), 0);
	}
	CHECK_EQ(pins_gpio_mask(PA), 0xFF);
	CHECK_EQ(pins_gpio_mask(PB), 0x0C);
	CHECK_EQ(pins_gpio_mask(PC), 0xFC);
	READ(RS, 2, "C0 00");
}

void board_tests(void)
{
	test_motor_failsafe();
	test_gpio_held();
	test_all_or_nothing();
	test_motors();
	test_servo_pins();
}
