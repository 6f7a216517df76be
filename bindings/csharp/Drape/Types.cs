// Blittable mirrors of the enums and structs in native/include/drape/drape.h.
//
// Rules (keep them when the header grows):
//  - [StructLayout(LayoutKind.Sequential)], fields in the header's order, the same widths:
//    uint32_t -> uint, int32_t -> int or an int-backed enum, float -> float, double -> double,
//    uint8_t -> byte, pointers -> pointers. No bool, no string, no array: every struct is
//    blittable, so P/Invoke passes a pointer to it and copies nothing.
//  - Sizes are asserted natively (capi_context.cpp, capi_garments.cpp) and in Drape.Tests
//    (StructLayoutTests).
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

    /// <summary>drape_garment_fit: what proportions garments are cut for (those whose
    /// <see cref="GarmentDesc.Cut"/> is <see cref="GarmentCut.Context"/>, and by default every garment but
    /// trousers and long-sleeve templates: <see cref="GarmentCut.ByKind"/>).</summary>
    public enum GarmentFit : int
    {
        /// <summary>DRAPE_GARMENT_FIT_SHAPE: the body shape's standard proportions only. The default.</summary>
        Shape = 0,
        /// <summary>DRAPE_GARMENT_FIT_SKELETON: the tracked person's. At the first pose, when its limb joints are all
        /// tracked and no such garment has stepped yet, the garments are cut for that pose's bones before their
        /// first step; once the tracker has calibrated the bone lengths, every garment whose
        /// <see cref="GarmentDesc.Cut"/> follows the context is cut again for their bones and torso when those
        /// move its rest pose by 1 cm or more (GarmentStats.Refits counts it; particles and triangles stay, the
        /// rest shape changes): made in the calibration's step, dressed two frames a step beside the old cut,
        /// swapped in 9 steps later with the default dress time.</summary>
        Skeleton = 1,
    }

    /// <summary>drape_garment_cut: what proportions one garment is cut for (GarmentDesc.Cut).</summary>
    public enum GarmentCut : int
    {
        /// <summary>DRAPE_GARMENT_CUT_CONTEXT: as the context's <see cref="ContextDesc.GarmentFit"/> (a zero-filled
        /// desc).</summary>
        Context = 0,
        /// <summary>DRAPE_GARMENT_CUT_SHAPE: the body shape's standard proportions, whatever the context's choice.</summary>
        Shape = 1,
        /// <summary>DRAPE_GARMENT_CUT_SKELETON: the tracked person's once the tracker has calibrated, whatever the
        /// context's choice (e.g. trousers on Kinect data beside a top cut for the shape).</summary>
        Skeleton = 2,
        /// <summary>DRAPE_GARMENT_CUT_BY_KIND: trousers and long-sleeve templates as <see cref="Skeleton"/>, every
        /// other garment as <see cref="Context"/>: legs and sleeves that reach the ankles and wrists stay round
        /// the person's limbs only when cut to their lengths, the shorter garments stretch less on the shape's
        /// cut (docs/garments.md, "Cut by kind"). When the tracked bones say the body shape is too small for the
        /// person (an adult on a 1.0-1.3 m shape), the T-shirt, skirt and dress templates are cut for the skeleton
        /// too, from the first pose (docs/garments.md, "A shape too small for the person"). The default
        /// (<see cref="GarmentDesc.CreateDefault"/>).</summary>
        ByKind = 3,
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

    /// <summary>drape_garment_kind: the procedural garment templates.</summary>
    public enum GarmentKind : int
    {
        /// <summary>DRAPE_GARMENT_TSHIRT: short sleeves; the default.</summary>
        TShirt = 0,
        /// <summary>DRAPE_GARMENT_LONG_SLEEVE.</summary>
        LongSleeve = 1,
        /// <summary>DRAPE_GARMENT_SKIRT.</summary>
        Skirt = 2,
        /// <summary>DRAPE_GARMENT_DRESS.</summary>
        Dress = 3,
        /// <summary>DRAPE_GARMENT_TROUSERS.</summary>
        Trousers = 4,
    }

    /// <summary>drape_solver: the cloth solver of a garment (fixed for its life).</summary>
    public enum Solver : int
    {
        /// <summary>DRAPE_SOLVER_XPBD: substepped XPBD, one iteration per substep; the default.</summary>
        Xpbd = 0,
        /// <summary>DRAPE_SOLVER_MASS_SPRING: the paper's mass-spring + explicit Euler (needs ~3 kHz substeps).</summary>
        MassSpring = 1,
    }

    /// <summary>drape_contact_response: how a particle inside an ellipsoid is pushed out.</summary>
    public enum ContactResponse : int
    {
        /// <summary>DRAPE_CONTACT_RADIAL: the paper's projection along the ray from the ellipsoid's centre.</summary>
        Radial = 0,
        /// <summary>DRAPE_CONTACT_EXACT: the closest point on the ellipsoid; the default.</summary>
        Exact = 1,
    }

    /// <summary>drape_mesh_facing (drape_mesh_fit.facing): which way the
    /// character a garment mesh was made for faces.</summary>
    public enum MeshFacing : int
    {
        /// <summary>0: the character faces +Z (MakeHuman, Blender's glTF export); the default.</summary>
        PlusZ = 0,
        /// <summary>1: the character faces -Z (Drape's own camera space).</summary>
        MinusZ = 1,
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
        /// <summary>garment_fit (int32_t in C); default <see cref="Drape.GarmentFit.Shape"/>.</summary>
        public GarmentFit GarmentFit;
        /// <summary>arms_clear_torso (int32_t 0 or 1): 1 (default) moves an arm ring that would run
        /// inside the torso (a hanging arm) out of it, <see cref="ArmTorsoClearanceM"/> apart, so
        /// sleeve and torso cloth both have room, and garments' upper sleeves also collide with the
        /// torso, so a hanging sleeve stays out of it; the body mesh's arms then sit up to a few
        /// centimetres off the tracked joints. 0 keeps every ring on its bone. See
        /// <see cref="IsArmsClearTorso"/>.</summary>
        public int ArmsClearTorso;
        /// <summary>arm_torso_clearance_m: gap kept between an arm ring and the torso ring beside it,
        /// [0, 0.05] m; default 0.01.</summary>
        public float ArmTorsoClearanceM;

        /// <summary><see cref="ArmsClearTorso"/> as a bool.</summary>
        public bool IsArmsClearTorso
        {
            get => ArmsClearTorso != 0;
            set => ArmsClearTorso = value ? 1 : 0;
        }

        /// <summary>The library's defaults (drape_context_desc_init_sized with this struct's size,
        /// so a library whose struct has grown never writes past it).</summary>
        public static unsafe ContextDesc CreateDefault()
        {
            DrapeLibrary.EnsureCompatible();
            ContextDesc d;
            DrapeException.Check(Native.drape_context_desc_init_sized(&d, (uint)sizeof(ContextDesc)));
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
        /// <summary>pose_jumped (uint8_t): 1 if the last update's frame was a pose jump (the torso, or a limb
        /// bone with both joints tracked, turned farther than a person can in the frame time; filters restarted,
        /// garments re-placed and put back when the pose returns).</summary>
        public byte PoseJumped;
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
        /// <summary>pose_jumps: pose jumps detected so far (docs/skeleton.md, "Pose jumps").</summary>
        public uint PoseJumps;

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
    /// |diag(1/Radii) * [AxisX AxisY AxisZ]^T (p - Centre)| &lt; 1. With the Drape rule the last five
    /// are fills: the pelvis fill (Chain = the torso, Ring = its hip ring, AxisY from between the
    /// thighs up to the hip ring; met by a template garment's torso cloth, not trousers', while both
    /// legs are tracked), the shoulder fills (right, then left: Chain = the arm, Ring = its junction ring,
    /// AxisY from the base of the neck to the shoulder joint; torso cloth collides with them too),
    /// then the hip fills (right, then left: Chain = the leg, Ring = its thigh ring, AxisY from the
    /// thigh ring up to the hip ring's side; cloth of that leg collides with them, and a template
    /// garment's torso cloth on that side while the leg is tracked).</summary>
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

    /// <summary>drape_garment_desc (24 bytes): how a garment is built, fixed for its life. Start
    /// from <see cref="CreateDefault"/>.</summary>
    [StructLayout(LayoutKind.Sequential)]
    public struct GarmentDesc
    {
        /// <summary>struct_size: sizeof(drape_garment_desc); set by CreateDefault.</summary>
        public uint StructSize;
        /// <summary>solver (int32_t in C); default <see cref="Drape.Solver.Xpbd"/>.</summary>
        public Solver Solver;
        /// <summary>area_density: kg/m^2, (0, 10]; default 0.2 (a light cotton shirt).</summary>
        public float AreaDensity;
        /// <summary>max_tethers: long-range attachments per particle, [0, 8]; default 2.</summary>
        public uint MaxTethers;
        /// <summary>dress_time_s: settling on the rest pose when added, [0, 10]; default 0.5.</summary>
        public float DressTimeS;
        /// <summary>cut (int32_t in C): what proportions this garment is cut for; default
        /// <see cref="GarmentCut.ByKind"/> (trousers and long sleeves for the person's skeleton, the rest as the
        /// context's <see cref="ContextDesc.GarmentFit"/> unless the body shape is too small for the person);
        /// <see cref="GarmentStats.Cut"/> says what it got.</summary>
        public GarmentCut Cut;

        /// <summary>The library's defaults (drape_garment_desc_init).</summary>
        public static unsafe GarmentDesc CreateDefault()
        {
            DrapeLibrary.EnsureCompatible();
            GarmentDesc d;
            DrapeException.Check(Native.drape_garment_desc_init(&d));
            return d;
        }
    }

    /// <summary>drape_garment_template (24 bytes): a procedural garment sized to the context's
    /// body shape. Start from <see cref="CreateDefault(GarmentKind)"/>.</summary>
    [StructLayout(LayoutKind.Sequential)]
    public struct GarmentTemplate
    {
        /// <summary>struct_size: sizeof(drape_garment_template); set by CreateDefault.</summary>
        public uint StructSize;
        /// <summary>kind (int32_t in C); default <see cref="GarmentKind.TShirt"/>.</summary>
        public GarmentKind Kind;
        /// <summary>particles: target particle count, [200, 200000] (the result is within -5 / +2.5 % from 1000 up, 10 % below); default 2000.
        /// Coarser than about 500 (long sleeve, trousers, dress, skirt) or 300 (T-shirt), limbs leave their tubes
        /// on the shared takes (docs/cloth-solver.md, "Coarse garments come off").</summary>
        public uint Particles;
        /// <summary>ease_m: clearance over the body, [0.002, 0.1]; default 0.025 (a long sleeve: 2 cm more at the
        /// armhole, tapering to 0.6 of it at the cuff).</summary>
        public float EaseM;
        /// <summary>length_scale: hem / sleeve / leg lengths, [0.5, 1.5]; default 1.</summary>
        public float LengthScale;
        /// <summary>reserved: 0.</summary>
        public uint Reserved;

        /// <summary>The library's defaults (drape_garment_template_init), a T-shirt.</summary>
        public static GarmentTemplate CreateDefault() => CreateDefault(GarmentKind.TShirt);

        /// <summary>The library's defaults (drape_garment_template_init) with <see cref="Kind"/> = <paramref name="kind"/>.</summary>
        public static unsafe GarmentTemplate CreateDefault(GarmentKind kind)
        {
            DrapeLibrary.EnsureCompatible();
            GarmentTemplate t;
            DrapeException.Check(Native.drape_garment_template_init(&t));
            t.Kind = kind;
            return t;
        }
    }

    /// <summary>drape_cloth_params (136 bytes): the cloth parameters of a garment; they may change
    /// at any time (<see cref="Garment.Params"/>). Start from <see cref="CreateDefault"/>. Ranges are
    /// checked by the library as a whole: NaN/Inf gives <see cref="ResultCode.NonFinite"/>, a value
    /// outside its range <see cref="ResultCode.OutOfRange"/>.</summary>
    [StructLayout(LayoutKind.Sequential)]
    public struct ClothParams
    {
        /// <summary>struct_size: sizeof(drape_cloth_params); set by CreateDefault.</summary>
        public uint StructSize;
        /// <summary>substep_hz: substeps per simulated second, [30, 20000]; default 300.</summary>
        public float SubstepHz;
        /// <summary>max_substeps: per step, [1, 1000]; default 200 (longer steps get longer substeps).</summary>
        public uint MaxSubsteps;
        /// <summary>max_step_s: a longer dt simulates only this much cloth time, [1e-4, 1]; default 0.1.</summary>
        public float MaxStepS;
        /// <summary>gravity: m/s^2, |g| &lt;= 1000 per component; default (0, -9.81, 0).</summary>
        public Vector3f Gravity;
        /// <summary>wind: m/s, |w| &lt;= 1000 per component; default 0.</summary>
        public Vector3f Wind;
        /// <summary>drag: 1/s, pulls velocity towards the wind, [0, 1000]; default 0.</summary>
        public float Drag;
        /// <summary>damping: 1/s, [0, 1000]; default 1.</summary>
        public float Damping;
        /// <summary>max_speed: m/s speed clamp, [0, 1000], 0 = none; default 20.</summary>
        public float MaxSpeed;
        /// <summary>stretch_compliance: XPBD compliance (m/N), [0, 1]; default 0 (inextensible).</summary>
        public float StretchCompliance;
        /// <summary>shear_compliance: [0, 1]; default 1e-6.</summary>
        public float ShearCompliance;
        /// <summary>bend_compliance: [0, 1]; default 1e-3.</summary>
        public float BendCompliance;
        /// <summary>tether_compliance: [0, 1]; default 0.</summary>
        public float TetherCompliance;
        /// <summary>tether_scale: a particle stays within rest * scale of its anchor, [1, 10]; default 1.1.</summary>
        public float TetherScale;
        /// <summary>static_friction: [0, 10]; default 0.6.</summary>
        public float StaticFriction;
        /// <summary>kinetic_friction: [0, 10]; default 0.4.</summary>
        public float KineticFriction;
        /// <summary>collision_margin_m: gap kept outside the ellipsoids (cloth thickness), [0, 0.05]; default 0.004.</summary>
        public float CollisionMarginM;
        /// <summary>contact_response (int32_t in C); default <see cref="Drape.ContactResponse.Exact"/>.</summary>
        public ContactResponse ContactResponse;
        /// <summary>continuous_collision (uint32_t 0 or 1): swept test across each substep; default 1.
        /// See <see cref="IsContinuousCollision"/>.</summary>
        public uint ContinuousCollision;
        /// <summary>linear_inertia: [0, 1]: 1 physical, 0 carried rigidly with the pelvis; default 0.5.</summary>
        public float LinearInertia;
        /// <summary>angular_inertia: [0, 1]; default 0.5.</summary>
        public float AngularInertia;
        /// <summary>blend_in_s: first frame and teleports blend the new pose in over this much
        /// simulated time, [0, 2]; default 0.3 (on the first frame after the garment is carried
        /// into the pose from its rest pose: up to 1 s more, docs/garments.md).</summary>
        public float BlendInS;
        /// <summary>spring_stretch: mass-spring solver only, N/m, [0, 1e6]; default 100.</summary>
        public float SpringStretch;
        /// <summary>spring_shear: mass-spring solver only, N/m; default 20.</summary>
        public float SpringShear;
        /// <summary>spring_bend: mass-spring solver only, N/m; default 2.</summary>
        public float SpringBend;
        /// <summary>spring_damping: mass-spring solver only, N s/m along each spring; default 0.01.</summary>
        public float SpringDamping;
        /// <summary>iterations: XPBD constraint passes per substep, [1, 64]; default 1 (the
        /// mass-spring solver ignores it). 2 with <see cref="StrainLimit"/> 0.07 in 8
        /// <see cref="StrainLimitPasses"/>: a T-shirt's P99 stretch 13.2 -> 11.7 % and its worst
        /// frame's depth 6.4 -> 4.1 mm on the default scene for about 30 % more frame time, but long
        /// sleeves come off a waving arm (docs/benchmarks.md, "Each setting against Bullet from its
        /// own shirt").</summary>
        public uint Iterations;
        /// <summary>strain_limit: XPBD, at the end of every step the structural edges longer than
        /// rest * (1 + StrainLimit) are pulled back to that length (<see cref="StrainLimitPasses"/>
        /// passes, before the last collision), [0, 10], 0 = off; default 0.1. The mass-spring solver
        /// ignores it.</summary>
        public float StrainLimit;
        /// <summary>collision_stride: XPBD, collide with the ellipsoids every Nth substep (the swept
        /// test spans the N substeps), [0, 8]; default 0: by the garment's resolution, every substep
        /// for 300 to 1 250 particles (coarse sleeves and trouser legs otherwise come off the limbs)
        /// and every second one outside. 1 costs about twice the collision time of 2. The mass-spring
        /// solver collides every substep and ignores it. Added after the rest (the struct grew from
        /// 128 to 132 bytes); the library still accepts the 128-byte layout.</summary>
        public uint CollisionStride;
        /// <summary>strain_limit_passes: XPBD, Gauss-Seidel passes of the strain limit at the end of
        /// each step, [1, 16]; default 2. Each pass costs about 4 us at 2 000 particles; with a
        /// tighter <see cref="StrainLimit"/> more passes stretch less (0.05 with 8 passes: the P99
        /// stretch of T-shirts, skirts, dresses and trousers 15-18 % lower on the shared takes for
        /// about 6 % more frame time; docs/garments.md, "More strain-limit passes"). Added after
        /// <see cref="CollisionStride"/> (132 to 136 bytes); the library still accepts the older
        /// layouts and gives them the default.</summary>
        public uint StrainLimitPasses;

        /// <summary><see cref="ContinuousCollision"/> as a bool.</summary>
        public bool IsContinuousCollision
        {
            get => ContinuousCollision != 0;
            set => ContinuousCollision = value ? 1u : 0u;
        }

        /// <summary>The library's defaults (drape_cloth_params_init_sized with this struct's size,
        /// as the C header's drape_cloth_params_init).</summary>
        public static unsafe ClothParams CreateDefault()
        {
            DrapeLibrary.EnsureCompatible();
            ClothParams p;
            DrapeException.Check(Native.drape_cloth_params_init_sized(&p, (uint)sizeof(ClothParams)));
            return p;
        }
    }

    /// <summary>drape_mesh_fit (48 bytes): how a garment mesh made for another body is placed on
    /// this one (docs/garment-obj.md). The defaults (<see cref="CreateDefault"/>) fit MakeHuman
    /// garments: decimetres, facing +Z, A-pose, a 1.60 m / 46.3 kg base mesh.</summary>
    [StructLayout(LayoutKind.Sequential)]
    public struct MeshFit
    {
        /// <summary>struct_size: sizeof(drape_mesh_fit); set by CreateDefault.</summary>
        public uint StructSize;
        /// <summary>unit_scale: metres per mesh unit, [0, 1000]; default 0 = detect (1, 0.1, 0.01, 0.001).</summary>
        public float UnitScale;
        /// <summary>facing: drape_mesh_facing; default <see cref="MeshFacing.PlusZ"/>.</summary>
        public MeshFacing Facing;
        /// <summary>source_height_m: the body the mesh was made for, [0.8, 2.5]; default 1.60.</summary>
        public float SourceHeightM;
        /// <summary>source_weight_kg: [15, 300]; default 46.3.</summary>
        public float SourceWeightKg;
        /// <summary>source_floor_y_m: where that body's feet are, after scaling, [-100, 100]; default -0.82.</summary>
        public float SourceFloorYM;
        /// <summary>source_axis_z_m: z of that body's vertical axis, after scaling, [-100, 100]; default 0.05.</summary>
        public float SourceAxisZM;
        /// <summary>source_arm_down_deg: its upper arms below horizontal, [0, 90]; default 50.</summary>
        public float SourceArmDownDeg;
        /// <summary>source_elbow_flex_deg: its elbows bent forward, [0, 150]; default 45.</summary>
        public float SourceElbowFlexDeg;
        /// <summary>source_leg_spread_deg: its legs turned outward, [0, 45]; default 6.</summary>
        public float SourceLegSpreadDeg;
        /// <summary>blend_m: soft choice of the body segment a vertex follows, [0, 0.2]; default 0.015.</summary>
        public float BlendM;
        /// <summary>reserved: 0.</summary>
        public uint Reserved;

        /// <summary>The library's defaults (drape_mesh_fit_init): MakeHuman garments.</summary>
        public static unsafe MeshFit CreateDefault()
        {
            DrapeLibrary.EnsureCompatible();
            MeshFit f;
            DrapeException.Check(Native.drape_mesh_fit_init(&f));
            return f;
        }
    }

    /// <summary>drape_garment_stats (104 bytes): what the garment's last step did.</summary>
    [StructLayout(LayoutKind.Sequential)]
    public struct GarmentStats
    {
        /// <summary>struct_size: sizeof(drape_garment_stats); set by the reading method.</summary>
        public uint StructSize;
        /// <summary>particles.</summary>
        public uint Particles;
        /// <summary>attached: particles pinned to body rings.</summary>
        public uint Attached;
        /// <summary>substeps: in the last step (blend-in frames included).</summary>
        public uint Substeps;
        /// <summary>blend_frames: extra 1/30 s frames the last step ran to blend a new pose in.</summary>
        public uint BlendFrames;
        /// <summary>contacts: particle-ellipsoid corrections in the last step.</summary>
        public uint Contacts;
        /// <summary>swept_catches: of which caught by the swept test.</summary>
        public uint SweptCatches;
        /// <summary>escapes: particles squeezed between overlapping ellipsoids.</summary>
        public uint Escapes;
        /// <summary>steps (uint64_t): steps so far.</summary>
        public ulong Steps;
        /// <summary>teleport_reset (uint8_t): 1 if the last step carried the garment across a teleport.</summary>
        public byte TeleportReset;
        /// <summary>nan_reset (uint8_t): 1 if the last step had to restore the garment (please report).</summary>
        public byte NanReset;
        /// <summary>cut (uint8_t): what the garment is cut for, its desc's <see cref="GarmentDesc.Cut"/> resolved,
        /// as a <see cref="GarmentFit"/> value (<see cref="CutFit"/>).</summary>
        public byte Cut;
        /// <summary>reserved1.</summary>
        public byte Reserved1;
        /// <summary>refits: times the garment was cut again (a body shape change, the skeleton's calibration:
        /// <see cref="Drape.GarmentFit"/>); its rest shape changes then, nothing else.</summary>
        public uint Refits;
        /// <summary><see cref="Cut"/> as a <see cref="GarmentFit"/> (<see cref="GarmentFit.Skeleton"/>: cut again for
        /// the person once the tracker calibrates).</summary>
        public GarmentFit CutFit => (GarmentFit)Cut;
        /// <summary>step_ms: wall time of the garment's last step.</summary>
        public double StepMs;
        /// <summary>collide_ms: of which ellipsoid collision; 0 on the OpenCL backend, where collision
        /// runs inside the device frame (integrate_ms then holds the whole frame).</summary>
        public double CollideMs;
        /// <summary>integrate_ms: the rest (integration and constraints).</summary>
        public double IntegrateMs;
        /// <summary>device_upload_ms: OpenCL backend, host to device writes of the last step's device
        /// frames (the queue's profiling events). The four device_* fields are 0 on the CPU backend and
        /// when the frame ran batched with other garments' (a batch is timed as a whole).</summary>
        public double DeviceUploadMs;
        /// <summary>device_kernel_ms: the first launch's start to the last one's end.</summary>
        public double DeviceKernelMs;
        /// <summary>device_readback_ms: positions (and normals when read) back to the host.</summary>
        public double DeviceReadbackMs;
        /// <summary>device_host_ms: the host packing the frame before the uploads. What
        /// <see cref="IntegrateMs"/> holds beyond the four is the host enqueueing and waiting.</summary>
        public double DeviceHostMs;

        /// <summary><see cref="TeleportReset"/> as a bool.</summary>
        public bool IsTeleportReset => TeleportReset != 0;
        /// <summary><see cref="NanReset"/> as a bool.</summary>
        public bool IsNanReset => NanReset != 0;
    }

    /// <summary>drape_garment_accuracy (40 bytes; 32 before the openings): how accurate the garment
    /// is now (a diagnostic, about 0.6 ms per 1 000 particles).</summary>
    [StructLayout(LayoutKind.Sequential)]
    public struct GarmentAccuracy
    {
        /// <summary>struct_size: sizeof(drape_garment_accuracy); set by the reading method.</summary>
        public uint StructSize;
        /// <summary>proxy_inside: particles inside an ellipsoid they collide with, by more than 0.1 mm.</summary>
        public uint ProxyInside;
        /// <summary>max_stretch: structural edges, max of |len| / rest - 1.</summary>
        public float MaxStretch;
        /// <summary>p99_stretch: its 99th percentile.</summary>
        public float P99Stretch;
        /// <summary>mean_stretch.</summary>
        public float MeanStretch;
        /// <summary>body_penetration_p99_mm: depth of vertices inside the body mesh (0 before an update);
        /// inside = winding number >= 1, depth = distance to the mesh.</summary>
        public float BodyPenetrationP99Mm;
        /// <summary>body_penetration_max_mm.</summary>
        public float BodyPenetrationMaxMm;
        /// <summary>deeper_than_2mm: fraction of vertices more than 2 mm inside the body.</summary>
        public float DeeperThan2mm;
        /// <summary>openings: the garment's openings (boundary loops: hem, collar, sleeve cuffs, trouser
        /// legs) that went round a body part when it was dressed.</summary>
        public uint Openings;
        /// <summary>openings_off: of those, the ones off their body part now (a sleeve the arm has
        /// left).</summary>
        public uint OpeningsOff;
        /// <summary>inside_body: fraction of vertices inside the body mesh at any depth (winding number
        /// &gt;= 1), how ANCHORS.md counts "cloth inside the body" (NvCloth 0.40 %); 0 before an update.</summary>
        public float InsideBody;
    }
}
