/* For running fovea.exe under Wine only, never shipped: Rust's standard library imports
 * ProcessPrng from bcryptprimitives.dll (Windows 10 and later), which Debian's Wine 8.0 lacks.
 * This stand-in fills the buffer from RtlGenRandom (advapi32's SystemFunction036), the
 * system's cryptographic generator. tools/wine-check.sh builds it and puts it beside the exe. */
#include <windows.h>

BOOLEAN WINAPI SystemFunction036(PVOID buffer, ULONG length);

BOOL WINAPI ProcessPrng(PBYTE data, SIZE_T length) {
    while (length > 0) {
        ULONG chunk = length > 0x10000000 ? 0x10000000 : (ULONG)length;
        if (!SystemFunction036(data, chunk)) return FALSE;
        data += chunk;
        length -= chunk;
    }
    return TRUE;
}
