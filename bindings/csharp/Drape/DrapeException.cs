using System;

namespace Drape
{
    /// <summary>A Drape call failed: <see cref="Code"/> is the drape_result it returned and
    /// <see cref="NativeMessage"/> the library's drape_last_error() text for that call.</summary>
    public sealed class DrapeException : Exception
    {
        /// <summary>The result code the native call returned (never <see cref="ResultCode.Ok"/>).</summary>
        public ResultCode Code { get; }

        /// <summary>drape_last_error() read on the calling thread right after the failed call.</summary>
        public string NativeMessage { get; }

        /// <summary>Creates the exception (the message combines the code's name and the native text).</summary>
        public DrapeException(ResultCode code, string nativeMessage)
            : base(Format(code, nativeMessage))
        {
            Code = code;
            NativeMessage = nativeMessage;
        }

        private static string Format(ResultCode code, string nativeMessage) =>
            nativeMessage.Length == 0 ? $"Drape: {code}" : $"Drape: {code}: {nativeMessage}";

        /// <summary>Throws a <see cref="DrapeException"/> unless <paramref name="result"/> is Ok. Must run on
        /// the thread that made the call, before any other Drape call (drape_last_error is per thread).</summary>
        internal static void Check(ResultCode result)
        {
            if (result != ResultCode.Ok) throw FromLastError(result);
        }

        internal static DrapeException FromLastError(ResultCode result) =>
            new DrapeException(result, Utf8.FromNative(Native.drape_last_error()));
    }
}
