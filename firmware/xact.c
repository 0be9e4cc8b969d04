#include "firmware/xact.h"

typedef enum {
	XACT_IDLE = 0,
	XACT_SELECT,    /* write frame: the register byte comes next */
	XACT_DATA,      /* write frame: data bytes */
	XACT_REFUSED,   /* write frame refused: the rest is refused too */
	XACT_READ,      /* read frame */
	XACT_NO_DATA,   /* read frame of a register that gives nothing */
} xact_state_t;

static struct {
	uint8_t state;
	uint8_t refusal;  /* why a refused write frame was refused */
	uint8_t *buf;
	uint8_t cap;
	uint8_t len;      /* write: data bytes held; read: bytes answered */
	uint8_t pos;      /* read: bytes given to the master */
} xact;

void xact_init(void)
{
	xact.state = XACT_IDLE;
}

void xact_frame_drop(void)
{
	if (xact.state == XACT_DATA && xact.len > 0) {
		regmap_set_status(REG_DROPPED);
	}
	xact.state = XACT_IDLE;
}

void xact_write_requested(uint8_t *buf, uint8_t cap)
{
	xact.state = XACT_SELECT;
	xact.buf = buf;
	xact.cap = cap;
	xact.len = 0;
}

static bool xact_refuse(reg_status_t why)
{
	xact.state = XACT_REFUSED;
	xact.refusal = why;
	regmap_set_status(why);
	return false;
}

bool xact_write_select(uint8_t reg)
{
	/* After an unmapped register none is selected (regmap.h): a read
	 * then gives nothing, not the register selected before. */
	if (!regmap_select(reg)) {
		return xact_refuse(REG_NO_REGISTER);
	}
	xact.state = XACT_DATA;
	return true;
}

bool xact_write_received(uint8_t byte)
{
	switch (xact.state) {
	case XACT_SELECT:
		return xact_write_select(byte);
	case XACT_DATA: {
		/* as xact_write_taken(1), in place: a TWI slave's path a byte,
		 * in its interrupt, as short as before that function */
		if (xact.len >= xact.cap) {
			return xact_refuse(REG_BAD_LENGTH);
		}
		xact.buf[xact.len++] = byte;
		reg_status_t st = regmap_check(xact.buf, xact.len);
		if (st != REG_OK) {
			return xact_refuse(st);
		}
		return true;
	}
	default:
		return false;
	}
}

bool xact_write_taken(uint8_t n)
{
	if (xact.state != XACT_DATA) {
		return false;  /* refused already (or its register byte was) */
	}
	/* Refused as early as it is known (the buffer is full, the driver
	 * can take no write that starts so), so a TWI slave can refuse the
	 * byte after it. */
	uint8_t len = xact.len;
	if (n > (uint8_t)(xact.cap - len)) {
		return xact_refuse(REG_BAD_LENGTH);
	}
	xact.len = (uint8_t)(len + n);
	reg_status_t st = regmap_check_from(xact.buf, len, xact.len);
	if (st != REG_OK) {
		return xact_refuse(st);
	}
	return true;
}

/* The driver's next answer goes after the bytes already answered, so a
 * front end that knows its read length can hand in the very bytes it
 * replies from; a full buffer starts over. */
static bool xact_refill(void)
{
	if (xact.len >= xact.cap) {
		xact.len = 0;
		xact.pos = 0;
	}
	uint8_t got = regmap_read(xact.buf + xact.len, (uint8_t)(xact.cap - xact.len));
	if (got == 0) {
		xact.state = XACT_NO_DATA;
		return false;
	}
	xact.len = (uint8_t)(xact.len + got);
	return true;
}

bool xact_read_requested(uint8_t *buf, uint8_t cap)
{
	xact.state = XACT_READ;
	xact.buf = buf;
	xact.cap = cap;
	xact.len = 0;
	xact.pos = 0;
	regmap_read_start();
	return xact_refill();
}

bool xact_read_processed(uint8_t *byte)
{
	if (xact.state != XACT_READ || (xact.pos >= xact.len && !xact_refill())) {
		*byte = 0xFF;
		return false;
	}
	*byte = xact.buf[xact.pos++];
	return true;
}

bool xact_read_take(uint8_t n)
{
	if (xact.state != XACT_READ) {
		return false;
	}
	while ((uint8_t)(xact.len - xact.pos) < n) {
		/* the bytes answered so far are taken; the driver answers on */
		n = (uint8_t)(n - (xact.len - xact.pos));
		xact.pos = xact.len;
		if (!xact_refill()) {
			return false;
		}
	}
	xact.pos = (uint8_t)(xact.pos + n);
	return true;
}

bool xact_write_pending(void)
{
	return xact.state == XACT_DATA && xact.len > 0;
}

bool xact_read_buffered(void)
{
	return xact.state != XACT_READ || xact.pos < xact.len;
}

reg_status_t xact_frame_end(void)
{
	reg_status_t st = REG_OK;

	if (xact.state == XACT_DATA && xact.len > 0) {
		st = regmap_write(xact.buf, xact.len);
	} else if (xact.state == XACT_REFUSED) {
		st = (reg_status_t)xact.refusal;
	}
	xact.state = XACT_IDLE;
	return st;
}
