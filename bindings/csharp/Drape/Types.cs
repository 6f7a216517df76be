// Blittable mirrors of the enums and structs in native/include/drape/drape.h.
//
// Rules (keep them when the header grows):
//  - [StructLayout(LayoutKind.Sequential)], fields in the header's order, the same widths:
//    uint32_t -> uint, int32_t -> int or an int-backed enum, float -> float, double -> double,
//    uint8_t -> byte, pointers -> pointers. No bool, no string, no array: every struct is
//    blittable, so P/Invoke passes a pointer to it and copies nothing.
//  - Sizes are asserted natively (capi_context.cpp) and in Drape.Tests (StructLayoutTests).
//  - Enum-typed fields are declared `: int`, the same 4 bytes as the C enum / int32_t they
//    replace; a value the binding does not know yet (from a newer library) is kept as is.
using System;
using System.Runtime.InteropServices;

namespace Drape
{
    /// <summary>drape_result: what every Drape call returns (0 = success).</summary>
    public enum ResultCode : int
    {
        /// <summary>DRAPE_OK.</summary>
        Ok = 0,
        /// <summary>DRAPE_ERROR_NULL_ARGUMENT: a required pointer was NULL.</summary>
        NullArgument = 1,
        /// <summary>DRAPE_ERROR_INVALID_ARGUMENT: a malformed value (bad struct_size, bad combination).</summary>
        InvalidArgument = 2,
        /// <summary>DRAPE_ERROR_INVALID_HANDLE: the handle is not a live object of the expected kind.</summary>
        InvalidHandle = 3,
        /// <summary>DRAPE_ERROR_BUFFER_TOO_SMALL: capacity below the size query's answer; nothing written.</summary>
        BufferTooSmall = 4,
        /// <summary>DRAPE_ERROR_NONFINITE: a NaN or Inf (or absurdly large) number was passed.</summary>
        NonFinite = 5,
        /// <summary>DRAPE_ERROR_OUT_OF_RANGE: a number or enum is outside its documented range.</summary>
        OutOfRange = 6,
        /// <summary>DRAPE_ERROR_CALL_ORDER: the call needs an earlier one (e.g. read before update).</summary>
        CallOrder = 7,
        /// <summary>DRAPE_ERROR_TIMESTAMP: a frame's timestamp is not after the previous frame's.</summary>
        Timestamp = 8,
        /// <summary>DRAPE_ERROR_IO: a file could not be opened or read.</summary>
        Io = 9,
        /// <summary>DRAPE_ERROR_PARSE: a file or buffer is not in a format Drape reads.</summary>
        Parse = 10,
        /// <summary>DRAPE_ERROR_OUT_OF_MEMORY.</summary>
        OutOfMemory = 11,
        /// <summary>DRAPE_ERROR_INTERNAL: a bug in Drape; please report it with the message.</summary>
        Internal = 12,
    }

    /// <summary>drape_layout: sensor joint layouts (joint order is the sensor SDK's own).</summary>
    public enum Layout : int
    {
        /// <summary>DRAPE_LAYOUT_AUTO: only where documented (recording readers).</summary>
        Auto = 0,
        /// <summary>DRAPE_LAYOUT_KINECT1: 20 joints, NUI_SKELETON_POSITION_INDEX order.</summary>
        Kinect1 = 1,
        /// <summary>DRAPE_LAYOUT_KINECT2: 25 joints, Kinect SDK 2.0 JointType order.</summary>
        Kinect2 = 2,
        /// <summary>DRAPE_LAYOUT_AZURE: 32 joints, k4abt_joint_id order, in metres.</summary>
        Azure = 3,
    }

    /// <summary>drape_tracking_state.</summary>
    public enum TrackingState : int
    {
        /// <summary>DRAPE_TRACKING_NOT_TRACKED.</summary>
        NotTracked = 0,
        /// <summary>DRAPE_TRACKING_INFERRED.</summary>
        Inferred = 1,
        /// <summary>DRAPE_TRACKING_TRACKED.</summary>
        Tracked = 2,
    }

    /// <summary>drape_filter: the skeleton filter of a context.</summary>
    public enum Filter : int
    {
        /// <summary>DRAPE_FILTER_NONE.</summary>
        None = 0,
        /// <summary>DRAPE_FILTER_ONE_EURO (Casiez et al. 2012); the default.</summary>
        OneEuro = 1,
        /// <summary>DRAPE_FILTER_DOUBLE_EXPONENTIAL: Kinect SDK-style Holt filter.</summary>
        DoubleExponential = 2,
    }

    /// <summary>drape_proxy_rule: how the tracking ellipsoids are built.</summary>
    public enum ProxyRule : int
    {
        /// <summary>DRAPE_PROXY_RULE_PAPER: the paper's eq. 5-6 (per torso ring, one per limb bone).</summary>
        Paper = 0,
        /// <summary>DRAPE_PROXY_RULE_DRAPE: per ring and sub-ring, sized to close the gaps; the default.</summary>
        Drape = 1,
    }

    /// <summary>drape_sex.</summary>
    public enum Sex : int
    {
        /// <summary>DRAPE_SEX_UNSPECIFIED.</summary>
        Unspecified = 0,
        /// <summary>DRAPE_SEX_FEMALE.</summary>
        Female = 1,
        /// <summary>DRAPE_SEX_MALE.</summary>
        Male = 2,
    }

    /// <summary>drape_recording_format, detected from a recording's content.</summary>
    public enum RecordingFormat : int
    {
        /// <summary>DRAPE_RECORDING_UNKNOWN.</summary>
        Unknown = 0,
        /// <summary>DRAPE_RECORDING_KINECT_CSV: timestamp ticks + N x (x, y, z, state).</summary>
        KinectCsv = 1,
        /// <summary>DRAPE_RECORDING_BVH: joints by forward kinematics, mapped to Kinect v2.</summary>
        Bvh = 2,
        /// <summary>DRAPE_RECORDING_DRAPE: Drape's own text format.</summary>
        Drape = 3,
    }

    /// <summary>drape_vec3 (12 bytes): metres, right-handed camera space. Same layout as
    /// UnityEngine.Vector3, so spans of either can be reinterpreted with MemoryMarshal.Cast.</summary>
    [StructLayout(LayoutKind.Sequential)]
    public struct Vector3f : IEquatable<Vector3f>
    {
        /// <summary>x.</summary>
        public float X;
        /// <summary>y.</summary>
        public float Y;
        /// <summary>z.</summary>
        public float Z;

        /// <summary>Creates a vector.</summary>
        public Vector3f(float x, float y, float z)
        {
            X = x;
            Y = y;
            Z = z;
        }

        /// <summary>True if no component is NaN or infinite.</summary>
        public bool IsFinite => float.IsFinite(X) && float.IsFinite(Y) && float.IsFinite(Z);

        /// <inheritdoc/>
        public bool Equals(Vector3f other) => X.Equals(other.X) && Y.Equals(other.Y) && Z.Equals(other.Z);
        /// <inheritdoc/>
        public override bool Equals(object? obj) => obj is Vector3f v && Equals(v);
        /// <inheritdoc/>
        public override int GetHashCode() => HashCode.Combine(X, Y, Z);
        /// <inheritdoc/>
        public override string ToString() => $"({X}, {Y}, {Z})";
    }

    /// <summary>drape_quat (16 bytes): x, y, z, w. Same layout as UnityEngine.Quaternion.</summary>
    [StructLayout(LayoutKind.Sequential)]
    public struct Quaternionf
    {
        /// <summary>x.</summary>
        public float X;
        /// <summary>y.</summary>
        public float Y;
        /// <summary>z.</summary>
        public float Z;
        /// <summary>w.</summary>
        public float W;

        /// <summary>Creates a quaternion.</summary>
        public Quaternionf(float x, float y, float z, float w)
        {
            X = x;
            Y = y;
            Z = z;
            W = w;
        }

        /// <summary>The identity rotation.</summary>
        public static Quaternionf Identity => new Quaternionf(0f, 0f, 0f, 1f);
    }

    /// <summary>drape_joint (16 bytes): one joint as the sensor reports it.</summary>
    [StructLayout(LayoutKind.Sequential)]
    public struct Joint
    {
        /// <summary>position: metres, camera space.</summary>
        public Vector3f Position;
        /// <summary>tracking_state (int32_t in C).</summary>
        public TrackingState TrackingState;

        /// <summary>Creates a joint.</summary>
        public Joint(Vector3f position, TrackingState trackingState)
        {
            Position = position;
            TrackingState = trackingState;
        }

        /// <inheritdoc/>
        public override string ToString() => $"{Position} {TrackingState}";
    }

    /// <summary>drape_context_desc (64 bytes). Start from <see cref="CreateDefault"/>, which
    /// sets <see cref="StructSize"/> and the library's defaults, then change what you need.</summary>
    [StructLayout(LayoutKind.Sequential)]
    public struct ContextDesc
    {
        /// <summary>struct_size: sizeof(drape_context_desc); set by CreateDefault.</summary>
        public uint StructSize;
        /// <summary>ring_points: points per feature ring, multiple of 4 in [8, 256]; default 20.</summary>
        public uint RingPoints;
        /// <summary>rings_per_segment: extra rings between two ring stations, [0, 16]; default 1.</summary>
        public uint RingsPerSegment;
        /// <summary>calibration_frames: frames over which bone lengths are measured, [1, 100000]; default 30.</summary>
        public uint CalibrationFrames;
        /// <summary>filter (int32_t in C); default <see cref="Drape.Filter.OneEuro"/>.</summary>
        public Filter Filter;
        /// <summary>filter_min_cutoff_hz: One-Euro minimum cutoff (Hz), &gt; 0.</summary>
        public float FilterMinCutoffHz;
        /// <summary>filter_beta: One-Euro speed coefficient, &gt;= 0.</summary>
        public float FilterBeta;
        /// <summary>filter_d_cutoff_hz: One-Euro derivative cutoff (Hz), &gt; 0.</summary>
        public float FilterDCutoffHz;
        /// <summary>smoothing: double exponential, [0, 1).</summary>
        public float Smoothing;
        /// <summary>correction: double exponential, [0, 1].</summary>
        public float Correction;
        /// <summary>prediction: double exponential, [0, 10].</summary>
        public float Prediction;
        /// <summary>jitter_radius_m: double exponential, &gt;= 0.</summary>
        public float JitterRadiusM;
        /// <summary>max_deviation_m: double exponential, &gt;= 0.</summary>
        public float MaxDeviationM;
        /// <summary>teleport_distance_m: pelvis jump reported as a teleport, (0, 100]; 0.5.</summary>
        public float TeleportDistanceM;
        /// <summary>proxy_rule (int32_t in C); default <see cref="Drape.ProxyRule.Drape"/>.</summary>
        public ProxyRule ProxyRule;
        /// <summary>reserved: 0.</summary>
        public uint Reserved;

        /// <summary>The library's defaults (drape_context_desc_init).</summary>
        public static unsafe ContextDesc CreateDefault()
        {
            DrapeLibrary.EnsureCompatible();
            ContextDesc d;
            DrapeException.Check(Native.drape_context_desc_init(&d));
            return d;
        }
    }

    /// <summary>drape_body_shape (48 bytes). Girths are circumferences in millimetres; 0 means
    /// "predict from height and weight". Start from <see cref="CreateDefault"/>.</summary>
    [StructLayout(LayoutKind.Sequential)]
    public struct BodyShape
    {
        /// <summary>struct_size: sizeof(drape_body_shape); set by CreateDefault.</summary>
        public uint StructSize;
        /// <summary>sex (int32_t in C).</summary>
        public Sex Sex;
        /// <summary>height_m: stature, [0.8, 2.5]; default 1.70.</summary>
        public float HeightM;
        /// <summary>weight_kg: [15, 300]; default 65.</summary>
        public float WeightKg;
        /// <summary>neck_mm: 0 or [50, 3000].</summary>
        public float NeckMm;
        /// <summary>chest_mm: 0 or [50, 3000].</summary>
        public float ChestMm;
        /// <summary>waist_mm: 0 or [50, 3000].</summary>
        public float WaistMm;
        /// <summary>hip_mm: 0 or [50, 3000].</summary>
        public float HipMm;
        /// <summary>thigh_mm: 0 or [50, 3000].</summary>
        public float ThighMm;
        /// <summary>calf_mm: 0 or [50, 3000].</summary>
        public float CalfMm;
        /// <summary>upper_arm_mm: 0 or [50, 3000].</summary>
        public float UpperArmMm;
        /// <summary>forearm_mm: 0 or [50, 3000].</summary>
        public float ForearmMm;

        /// <summary>The default body (drape_body_shape_init): 1.70 m, 65 kg, girths predicted.</summary>
        public static unsafe BodyShape CreateDefault()
        {
            DrapeLibrary.EnsureCompatible();
            BodyShape s;
            DrapeException.Check(Native.drape_body_shape_init(&s));
            return s;
        }
    }

    /// <summary>drape_skeleton_frame (40 bytes on 64-bit: 24 + two pointers). Built by
    /// <see cref="Context.PushSkeleton(ReadOnlySpan{Joint}, Layout, double)"/>; the pointers
    /// are only valid during that call.</summary>
    [StructLayout(LayoutKind.Sequential)]
    internal unsafe struct SkeletonFrame
    {
        public uint StructSize;
        public Layout Layout;
        public uint JointCount;
        public uint Reserved;
        public double TimestampS;
        public Joint* Joints;
        public Quaternionf* Orientations;
    }

    /// <summary>drape_frame_stats (72 bytes).</summary>
    [StructLayout(LayoutKind.Sequential)]
    public struct FrameStats
    {
        /// <summary>struct_size: sizeof(drape_frame_stats).</summary>
        public uint StructSize;
        /// <summary>frames_pushed: push calls (accepted + rejected).</summary>
        public uint FramesPushed;
        /// <summary>frames_accepted.</summary>
        public uint FramesAccepted;
        /// <summary>frames_rejected.</summary>
        public uint FramesRejected;
        /// <summary>frames_dropped: accepted but replaced before an update consumed them.</summary>
        public uint FramesDropped;
        /// <summary>updates: updates that consumed a new frame.</summary>
        public uint Updates;
        /// <summary>teleports: teleports detected so far.</summary>
        public uint Teleports;
        /// <summary>teleported (uint8_t): 1 if the last update's frame was a teleport.</summary>
        public byte Teleported;
        /// <summary>calibrated (uint8_t): 1 once bone lengths are frozen.</summary>
        public byte Calibrated;
        /// <summary>reserved0.</summary>
        public byte Reserved0;
        /// <summary>reserved1.</summary>
        public byte Reserved1;
        /// <summary>last_timestamp_s: of the last accepted frame.</summary>
        public double LastTimestampS;
        /// <summary>skeleton_ms: wall time of the last update's skeleton stage.</summary>
        public double SkeletonMs;
        /// <summary>body_ms: wall time of the last update's ring + mesh stage.</summary>
        public double BodyMs;
        /// <summary>proxies_ms: wall time of the last update's tracking-ellipsoid stage.</summary>
        public double ProxiesMs;
        /// <summary>body_volume_l: enclosed volume of the body mesh after the last update.</summary>
        public float BodyVolumeL;
        /// <summary>reserved2.</summary>
        public float Reserved2;

        /// <summary><see cref="Teleported"/> as a bool.</summary>
        public bool IsTeleported => Teleported != 0;
        /// <summary><see cref="Calibrated"/> as a bool.</summary>
        public bool IsCalibrated => Calibrated != 0;
    }

    /// <summary>drape_recording_info (32 bytes).</summary>
    [StructLayout(LayoutKind.Sequential)]
    public struct RecordingInfo
    {
        /// <summary>struct_size: sizeof(drape_recording_info).</summary>
        public uint StructSize;
        /// <summary>format (int32_t in C): detected from the content.</summary>
        public RecordingFormat Format;
        /// <summary>layout (int32_t in C): of the frames.</summary>
        public Layout Layout;
        /// <summary>joint_count.</summary>
        public uint JointCount;
        /// <summary>frame_count.</summary>
        public uint FrameCount;
        /// <summary>nominal_rate_hz: median frame rate.</summary>
        public float NominalRateHz;
        /// <summary>duration_s.</summary>
        public double DurationS;
    }

    /// <summary>drape_ellipsoid (68 bytes): one tracking ellipsoid. A world point p is inside when
    /// |diag(1/Radii) * [AxisX AxisY AxisZ]^T (p - Centre)| &lt; 1.</summary>
    [StructLayout(LayoutKind.Sequential)]
    public struct Ellipsoid
    {
        /// <summary>centre (metres).</summary>
        public Vector3f Centre;
        /// <summary>axis_x: body forward (limbs: carried along the limb without twist).</summary>
        public Vector3f AxisX;
        /// <summary>axis_y: along the bone.</summary>
        public Vector3f AxisY;
        /// <summary>axis_z: AxisX x AxisY.</summary>
        public Vector3f AxisZ;
        /// <summary>radii: semi-axes along AxisX, AxisY, AxisZ (metres).</summary>
        public Vector3f Radii;
        /// <summary>chain: 0 torso, 1 neck and head, 2 left arm, 3 right arm, 4 left leg, 5 right leg.</summary>
        public int Chain;
        /// <summary>ring: the feature ring it was built from.</summary>
        public int Ring;
    }

    /// <summary>drape_proxy_fidelity (40 bytes): how closely the ellipsoids follow the body mesh.</summary>
    [StructLayout(LayoutKind.Sequential)]
    public struct ProxyFidelity
    {
        /// <summary>struct_size: sizeof(drape_proxy_fidelity); set by the reading method.</summary>
        public uint StructSize;
        /// <summary>union_samples: surface points of the union measured.</summary>
        public uint UnionSamples;
        /// <summary>body_to_proxy_mean_mm: body vertices' distance outside the union (mean).</summary>
        public float BodyToProxyMeanMm;
        /// <summary>body_to_proxy_p95_mm.</summary>
        public float BodyToProxyP95Mm;
        /// <summary>body_to_proxy_max_mm.</summary>
        public float BodyToProxyMaxMm;
        /// <summary>proxy_to_body_mean_mm: the union's distance outside the body (mean).</summary>
        public float ProxyToBodyMeanMm;
        /// <summary>proxy_to_body_p95_mm.</summary>
        public float ProxyToBodyP95Mm;
        /// <summary>proxy_to_body_max_mm.</summary>
        public float ProxyToBodyMaxMm;
        /// <summary>outside_fraction: body vertices outside every ellipsoid by more than 0.5 mm.</summary>
        public float OutsideFraction;
        /// <summary>reserved.</summary>
        public float Reserved;
    }
}
