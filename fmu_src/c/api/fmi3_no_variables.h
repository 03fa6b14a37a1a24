/* fmi3Get<T>/fmi3Set<T> of the types the FMI 3.0 FMUs have no variables of, clocks and binaries included (the native
   fmi3_api.c and the Python FMU's loader3.c): each refuses a non-empty call with fmi3Error and
   "this FMU has no <T> variables".  Include after defining
   static fmi3Status no_variables(fmi3Instance, size_t nvr, const char *function, const char *type). */
#ifndef LCV_FMI3_NO_VARIABLES_H
#define LCV_FMI3_NO_VARIABLES_H

#define NO_GET(T, CT) \
fmi3Status fmi3Get##T(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, \
                      CT values[], size_t nValues) \
{ (void)valueReferences; (void)values; (void)nValues; \
  return no_variables(instance, nValueReferences, "fmi3Get" #T, #T); }
#define NO_SET(T, CT) \
fmi3Status fmi3Set##T(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, \
                      const CT values[], size_t nValues) \
{ (void)valueReferences; (void)values; (void)nValues; \
  return no_variables(instance, nValueReferences, "fmi3Set" #T, #T); }
NO_GET(Float32, fmi3Float32) NO_SET(Float32, fmi3Float32)
NO_GET(Int8, fmi3Int8) NO_SET(Int8, fmi3Int8)
NO_GET(UInt8, fmi3UInt8) NO_SET(UInt8, fmi3UInt8)
NO_GET(Int16, fmi3Int16) NO_SET(Int16, fmi3Int16)
NO_GET(UInt16, fmi3UInt16) NO_SET(UInt16, fmi3UInt16)
NO_GET(Int32, fmi3Int32) NO_SET(Int32, fmi3Int32)
NO_GET(UInt32, fmi3UInt32) NO_SET(UInt32, fmi3UInt32)
NO_GET(UInt64, fmi3UInt64) NO_SET(UInt64, fmi3UInt64)
NO_GET(Boolean, fmi3Boolean) NO_SET(Boolean, fmi3Boolean)

fmi3Status fmi3GetBinary(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                         size_t valueSizes[], fmi3Binary values[], size_t nValues)
{
    (void)valueReferences; (void)valueSizes; (void)values; (void)nValues;
    return no_variables(instance, nValueReferences, "fmi3GetBinary", "Binary");
}

fmi3Status fmi3SetBinary(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                         const size_t valueSizes[], const fmi3Binary values[], size_t nValues)
{
    (void)valueReferences; (void)valueSizes; (void)values; (void)nValues;
    return no_variables(instance, nValueReferences, "fmi3SetBinary", "Binary");
}

fmi3Status fmi3GetClock(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                        fmi3Clock values[])
{
    (void)valueReferences; (void)values;
    return no_variables(instance, nValueReferences, "fmi3GetClock", "Clock");
}

fmi3Status fmi3SetClock(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                        const fmi3Clock values[])
{
    (void)valueReferences; (void)values;
    return no_variables(instance, nValueReferences, "fmi3SetClock", "Clock");
}

#endif
