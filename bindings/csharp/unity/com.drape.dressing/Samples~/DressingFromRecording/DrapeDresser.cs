// Drape sample (Unity): dresses the person a joint source sees and updates the garment's Mesh, and
// optionally a garment worn under it and the body's, every frame. The joint source is pluggable: any component implementing
// Drape.IJointSource (RecordingJointSourceBehaviour from the package, KinectV2JointSourceBehaviour
// below with DRAPE_KINECT_V2 defined, your own), or any IJointSource set from code (JointSource,
// e.g. an AzureKinectJointSource). docs/unity.md walks through the setup.
using System;
using Drape;
using UnityEngine;

namespace Drape.Samples
{
    /// <summary>
    /// Drives a <see cref="DressingLoop"/> from <c>Update()</c> and writes the garment (and body)
    /// vertices into Meshes. No managed allocation per frame: the vertex arrays are allocated once in
    /// OnEnable and the library writes into them directly (<see cref="DrapeUnity.AsDrape"/>).
    /// Disposes everything in OnDisable (native objects are never left to the garbage collector).
    /// </summary>
    [AddComponentMenu("Drape/Drape Dresser")]
    [DisallowMultipleComponent]
    public sealed class DrapeDresser : MonoBehaviour
    {
        [Header("Input")]
        [Tooltip("A component implementing Drape.IJointSource. Empty: the first one on this GameObject, unless JointSource was set from code.")]
        [SerializeField] private MonoBehaviour jointSource = null;

        [Header("Garment")]
        [SerializeField] private GarmentKind garment = GarmentKind.TShirt;
        [Tooltip("Cloth particles (0: the template's default, 2 000).")]
        [SerializeField] private int particles = 0;
        [Tooltip("What the garment is cut for: ByKind (the default: trousers and long sleeves cut again for the person's bones once the tracker has calibrated, so legs and sleeves end at the ankles and wrists; other garments as the context's GarmentFit), Context (the context's GarmentFit, the shape's standard proportions by default), Shape, or Skeleton (docs/garments.md, \"Cut by kind\").")]
        [SerializeField] private GarmentCut cut = GarmentCut.ByKind;
        [Tooltip("Receives the garment mesh (its sharedMesh is replaced).")]
        [SerializeField] private MeshFilter garmentMesh = null;
        [Tooltip("Normals from Drape (true) or Mesh.RecalculateNormals (false).")]
        [SerializeField] private bool drapeNormals = true;
        [Tooltip("Less stretch: the strain limit at 5 % in 8 passes instead of 10 % in 2 (ClothParams.StrainLimit, StrainLimitPasses) for both garments: T-shirts, skirts, dresses and trousers stretch 15-18 % less at the P99 for about 6 % more cloth time; a long sleeve on a waving arm can come off with it (docs/garments.md, \"More strain-limit passes\").")]
        [SerializeField] private bool lessStretch = false;

        [Header("Garment under it (optional)")]
        [Tooltip("Receives the mesh of a second garment worn under the first (its sharedMesh is replaced); leave empty for one garment. The first garment then lies on it (layers: docs/garments.md, \"Layered garments\").")]
        [SerializeField] private MeshFilter underMesh = null;
        [Tooltip("The garment worn under the first one (same particles and cut).")]
        [SerializeField] private GarmentKind underGarment = GarmentKind.Trousers;

        [Header("Body (optional)")]
        [Tooltip("Receives the body mesh; leave empty not to read the body.")]
        [SerializeField] private MeshFilter bodyMesh = null;
        [Tooltip("Arms kept clear of the torso (the default): a hanging arm's rings move out of the torso so the sleeve and the torso cloth both have room and the upper sleeves also collide with the torso, and the body's arms then sit up to a few centimetres off the tracked joints. Off: every ring on its bone, e.g. to overlay the body on the sensor's image (docs/body-model.md).")]
        [SerializeField] private bool armsClearTorso = true;

        [Header("Space")]
        [Tooltip("Drape's space is right-handed; X turns it into Unity's left-handed one as seen from the sensor.")]
        [SerializeField] private AxisFlip axisFlip = AxisFlip.X;

        private IJointSource _sourceFromCode;
        private DressingLoop _loop;
        private Garment _garment, _under;
        private Mesh _garmentMesh, _underMesh, _bodyMesh;
        private Vector3[] _garmentPositions, _garmentNormals, _underPositions, _underNormals, _bodyPositions, _bodyNormals;

        /// <summary>A joint source set from code (before the component is enabled); it wins over
        /// the serialized component.</summary>
        public IJointSource JointSource
        {
            get => _sourceFromCode;
            set => _sourceFromCode = value;
        }

        /// <summary>The running loop (null while disabled): its Context gives statistics and the body shape.</summary>
        public DressingLoop Loop => _loop;

        /// <summary>The garment (null while disabled).</summary>
        public Garment Garment => _garment;

        /// <summary>The garment worn under it (null while disabled or without an under mesh).</summary>
        public Garment UnderGarment => _under;

        private IJointSource FindSource()
        {
            if (_sourceFromCode != null) return _sourceFromCode;
            if (jointSource != null)
            {
                if (jointSource is IJointSource s) return s;
                throw new InvalidOperationException($"{jointSource.GetType().Name} does not implement Drape.IJointSource");
            }
            IJointSource onThis = GetComponent<IJointSource>();
            if (onThis != null) return onThis;
            throw new InvalidOperationException("DrapeDresser needs a joint source: set one in the inspector or JointSource from code");
        }

        private void OnEnable()
        {
            try
            {
                ContextDesc contextDesc = ContextDesc.CreateDefault();
                contextDesc.IsArmsClearTorso = armsClearTorso;
                _loop = new DressingLoop(FindSource(), contextDesc);
                GarmentTemplate tmpl = GarmentTemplate.CreateDefault(garment);
                if (particles > 0) tmpl.Particles = (uint)particles;
                GarmentDesc desc = GarmentDesc.CreateDefault();
                desc.Cut = cut;
                ClothParams cloth = ClothParams.CreateDefault();
                if (lessStretch)
                {
                    cloth.StrainLimit = 0.05f;
                    cloth.StrainLimitPasses = 8;
                }
                _garment = _loop.Context.AddGarment(tmpl, desc, cloth);

                _garmentPositions = new Vector3[_garment.VertexCount];
                _garmentNormals = new Vector3[_garment.VertexCount];
                var triangles = new int[_garment.IndexCount];
                MeshSpace.ReadGarmentTriangles(_garment, triangles, axisFlip);
                _garmentMesh = DrapeUnity.CreateDynamicMesh("Drape garment", _garmentPositions, triangles);
                if (garmentMesh != null) garmentMesh.sharedMesh = _garmentMesh;

                if (underMesh != null)
                {
                    GarmentTemplate underTmpl = GarmentTemplate.CreateDefault(underGarment);
                    if (particles > 0) underTmpl.Particles = (uint)particles;
                    _under = _loop.Context.AddGarment(underTmpl, desc, cloth);
                    _under.Layer = 1;     // next to the body
                    _garment.Layer = 2;   // lies on it
                    _underPositions = new Vector3[_under.VertexCount];
                    _underNormals = new Vector3[_under.VertexCount];
                    var underTriangles = new int[_under.IndexCount];
                    MeshSpace.ReadGarmentTriangles(_under, underTriangles, axisFlip);
                    _underMesh = DrapeUnity.CreateDynamicMesh("Drape garment under", _underPositions, underTriangles);
                    underMesh.sharedMesh = _underMesh;
                }

                if (bodyMesh != null)
                {
                    var (vertexCount, indexCount) = _loop.Context.GetBodyMeshSize();
                    _bodyPositions = new Vector3[vertexCount];
                    _bodyNormals = new Vector3[vertexCount];
                    var bodyTriangles = new int[indexCount];
                    MeshSpace.ReadBodyTriangles(_loop.Context, bodyTriangles, axisFlip);
                    _bodyMesh = DrapeUnity.CreateDynamicMesh("Drape body", _bodyPositions, bodyTriangles);
                    bodyMesh.sharedMesh = _bodyMesh;
                }
            }
            catch (Exception e)
            {
                Debug.LogError($"DrapeDresser: {e.Message}", this);
                Release();
                enabled = false;
            }
        }

        private void Update()
        {
            if (_loop == null) return;
            _loop.Tick(Time.deltaTime);
            if (!_loop.HasBody) return;   // no accepted frame yet

            WriteGarment(_garment, _garmentMesh, _garmentPositions, _garmentNormals);
            if (_underMesh != null) WriteGarment(_under, _underMesh, _underPositions, _underNormals);

            if (_bodyMesh != null)
            {
                MeshSpace.ReadBody(_loop.Context, _bodyPositions.AsDrape(), _bodyNormals.AsDrape(), axisFlip);
                _bodyMesh.SetVertices(_bodyPositions);
                _bodyMesh.SetNormals(_bodyNormals);
                _bodyMesh.RecalculateBounds();
            }
        }

        /// <summary>A garment's positions (and normals) straight into its arrays, then its Mesh.</summary>
        private void WriteGarment(Garment g, Mesh mesh, Vector3[] positions, Vector3[] normals)
        {
            MeshSpace.ReadGarment(g, positions.AsDrape(), drapeNormals ? normals.AsDrape() : Span<Vector3f>.Empty, axisFlip);
            mesh.SetVertices(positions);
            if (drapeNormals) mesh.SetNormals(normals);
            else mesh.RecalculateNormals();
            mesh.RecalculateBounds();
        }

        private void OnDisable() => Release();

        private void Release()
        {
            if (_loop != null) _loop.Dispose();   // the context and its garments
            _loop = null;
            _garment = null;
            _under = null;
            if (_garmentMesh != null) Destroy(_garmentMesh);
            if (_underMesh != null) Destroy(_underMesh);
            if (_bodyMesh != null) Destroy(_bodyMesh);
            _garmentMesh = null;
            _underMesh = null;
            _bodyMesh = null;
        }
    }
}
