/*
 * A loop of known instructions for the simulator's `profile` request
 * (tests/sim/test_profile.py): two NOPs (1 cycle each) and an RJMP back
 * (2 cycles), 4 cycles a turn, the first at the global label profile_loop.
 * Nothing else runs: no interrupt is on.
 */
int main(void)
{
	__asm__ __volatile__(
		".global profile_loop\n"
		"profile_loop:\n"
		"	nop\n"
		"	nop\n"
		"	rjmp profile_loop\n");
	return 0;
}
