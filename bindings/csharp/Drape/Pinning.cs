using System.Runtime.CompilerServices;

namespace Drape
{
    /// <summary>
    /// Pinning a ReadOnlySpan without <c>fixed (T* p = span)</c>. That statement compiles to
    /// <c>ReadOnlySpan&lt;T&gt;.GetPinnableReference()</c>, whose signature in the .NET Standard 2.1
    /// reference assembly returns <c>ref readonly T</c> with a <c>modreq(InAttribute)</c>; Mono 6's
    /// corlib (Debian's mono-complete 6.8) declares it without the modreq, so every such call throws
    /// MissingMethodException there (the same holds for the ReadOnlySpan indexer). The bindings pin
    /// with <c>fixed (T* p0 = &amp;MemoryMarshal.GetReference(span))</c> instead, whose signature
    /// (<c>ref T</c>) both runtimes share, and map an empty span to NULL as <c>fixed</c> does.
    /// (Span&lt;T&gt;, whose GetPinnableReference returns a plain <c>ref T</c>, is not affected.)
    /// </summary>
    internal static unsafe class Pinning
    {
        [MethodImpl(MethodImplOptions.AggressiveInlining)]
        public static T* OrNull<T>(T* pinned, int length) where T : unmanaged => length == 0 ? null : pinned;
    }
}
