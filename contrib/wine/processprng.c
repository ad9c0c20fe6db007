/*
 * ProcessPrng for Wine versions that lack it (Wine 8, Debian 12's): a
 * test-environment matter, not the program's. Rust's standard library
 * takes its random bytes (HashMap's keys) from ProcessPrng in
 * bcryptprimitives.dll, which Windows 10 and later have; without the DLL
 * every Rust program fails to start under such a Wine (status c0000135).
 *
 * scripts/cross.sh builds this with mingw into the Wine prefix's
 * system32 when Wine has no bcryptprimitives.dll of its own. It hands
 * the request to RtlGenRandom (advapi32's SystemFunction036), the
 * generator Rust used before ProcessPrng, which Wine does have.
 */
#include <windows.h>

/* RtlGenRandom: no import library names it by that name. */
BOOLEAN WINAPI SystemFunction036(PVOID buffer, ULONG length);

/* Windows' ProcessPrng always succeeds (it returns TRUE); RtlGenRandom
 * takes at most a ULONG a call, so larger requests go in pieces. */
__declspec(dllexport) BOOL WINAPI ProcessPrng(PBYTE data, SIZE_T length)
{
    while (length > 0) {
        ULONG piece = length > 0x10000000 ? 0x10000000 : (ULONG)length;
        if (!SystemFunction036(data, piece))
            return FALSE;
        data += piece;
        length -= piece;
    }
    return TRUE;
}
