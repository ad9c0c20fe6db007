/*
 * A stand-in for the control panel's preview, for testing screensaver.scr
 * /p under Wine (scripts/cross.sh windows): opens a 320 x 240 window,
 * prints its handle in decimal (what Windows passes after /p) on stdout,
 * and closes it after the seconds given as its argument (default 10), so
 * that the test sees whether the screen saver drew into it and whether it
 * ends when the window goes, as a preview must.
 */
#include <stdio.h>
#include <stdlib.h>
#include <windows.h>

static LRESULT CALLBACK procedure(HWND window, UINT message, WPARAM w, LPARAM l)
{
    switch (message) {
    case WM_TIMER:
        DestroyWindow(window);
        return 0;
    case WM_DESTROY:
        PostQuitMessage(0);
        return 0;
    }
    return DefWindowProcW(window, message, w, l);
}

int main(int argc, char **argv)
{
    int seconds = argc > 1 ? atoi(argv[1]) : 10;
    WNDCLASSW class = {0};
    class.lpfnWndProc = procedure;
    class.hInstance = GetModuleHandleW(NULL);
    class.hbrBackground = (HBRUSH)GetStockObject(WHITE_BRUSH);
    class.lpszClassName = L"PreviewHost";
    if (!RegisterClassW(&class))
        return 1;
    /* Where the test's screenshot looks: the top left of the screen, no
     * frame, white until something draws over it. */
    HWND window = CreateWindowExW(0, L"PreviewHost", L"Preview host", WS_POPUP | WS_VISIBLE | WS_CLIPCHILDREN,
                                  0, 0, 320, 240, NULL, NULL, class.hInstance, NULL);
    if (!window)
        return 1;
    printf("%llu\n", (unsigned long long)(UINT_PTR)window);
    fflush(stdout);
    SetTimer(window, 1, (UINT)seconds * 1000, NULL);
    MSG message;
    while (GetMessageW(&message, NULL, 0, 0) > 0) {
        TranslateMessage(&message);
        DispatchMessageW(&message);
    }
    return 0;
}
